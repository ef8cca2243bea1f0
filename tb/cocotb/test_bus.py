"""cocotb test of the bus slave (`rmapgen generate --bus wishbone|axi4-lite`), driven by the
ecosystem's bus masters: cocotbext-wishbone's WishboneMaster or cocotbext-axi's AxiLiteMaster.

Everything about the design is read from the generated directory (the simulator's working
directory): manifest.json gives the bus, the register map and the vector file with its fields;
the register constants are the design's own Python view (<prefix>rmap_regs.py), so the test
also checks that view against the Verilog. Nothing here restates an offset or a width.

- registers: every register read; the identification block equals the Python view's
  constants, the status registers hold 0 out of reset, CONTROL reads 0.
- refusals: an address no register has, a write to a read-only register, a read of a window,
  a partial write and (a design without a loaded table) a table write are each answered with
  an error and change nothing; ERRORS counts them, CONTROL.CLEAR_ERRORS clears it.
- frame: the map-0 samples stream as one frame (random bubbles{, backpressure}) while the
  second map is written back to back through the windows; the swap is requested inside the
  frame and must wait for its last sample (STATUS.SWAP_PENDING read high meanwhile); a window
  write right after the swap must wait until every sample accepted before the swap has left;
  FRAMES counts one swap; the map-1 samples follow as the next frame. Every result is compared
  with the model's, exactly.

Environment: RMAP_LIMIT=N takes only the first N samples of each map part; RMAP_PLANT=expected
corrupts one expected value (a planted fault the test must report; tb/cocotb/run_bus.py).
"""

import importlib.util
import json
import os
import random
from pathlib import Path

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, RisingEdge

SEED = 61
TIMEOUT = 5000  # clocks without progress


def design():
    """The manifest, the bus part of it and the design's Python view of the registers."""
    man = json.loads(Path("manifest.json").read_text())
    bus = man["bus"]
    py = next(f for f in bus["files"] if f.endswith(".py"))
    spec = importlib.util.spec_from_file_location("rmap_regs_view", py)
    regs = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(regs)
    return man, bus, regs


class Bus:
    """Word accesses on the design's bus: read(offset) -> (data, refused), write(offset,
    value, strobe) -> refused. Offsets are byte offsets, as the register map gives them."""

    def __init__(self, dut, kind):
        self.kind = kind
        if kind == "wishbone":
            from cocotbext.wishbone.driver import WishboneMaster
            signals = {"cyc": "cyc_i", "stb": "stb_i", "we": "we_i", "adr": "adr_i",
                       "datwr": "dat_i", "datrd": "dat_o", "ack": "ack_o", "err": "err_o",
                       "sel": "sel_i"}
            self.m = WishboneMaster(dut, "wb", dut.clk_i, width=32, timeout=TIMEOUT,
                                    signals_dict=signals)
        else:
            from cocotbext.axi import AxiLiteBus, AxiLiteMaster
            self.m = AxiLiteMaster(AxiLiteBus.from_prefix(dut, "s_axil"), dut.clk_i, dut.rst_ni,
                                   reset_active_level=False)

    async def read(self, offset):
        if self.kind == "wishbone":
            from cocotbext.wishbone.driver import WBOp
            r = (await self.m.send_cycle([WBOp(offset >> 2)]))[0]
            return int(r.datrd), r.ack == 2
        r = await self.m.read(offset, 4)
        return int.from_bytes(r.data, "little"), int(r.resp) != 0

    async def write(self, offset, value, strobe=0xF):
        if self.kind == "wishbone":
            from cocotbext.wishbone.driver import WBOp
            r = (await self.m.send_cycle([WBOp(offset >> 2, value, sel=strobe)]))[0]
            return r.ack == 2
        data = value.to_bytes(4, "little")
        if strobe != 0xF:
            # A partial write: the bytes the strobe selects (one byte at the offset).
            assert strobe == 0x1
            data = data[:1]
        r = await self.m.write(offset, data)
        return int(r.resp) != 0


async def start(dut, kind):
    """Clock, the bus master (its signals driven idle from the start), reset, and every
    sample input quiet."""
    cocotb.start_soon(Clock(dut.clk_i, 10, unit="ns").start())
    dut.rst_ni.value = 0
    # AXI4-Lite's channels must be idle through reset (cocotbext-axi drives them from its
    # construction); the Wishbone master is made after reset, its first cycle then.
    bus = Bus(dut, kind) if kind != "wishbone" else None
    dut.valid_i.value = 0
    dut.last_i.value = 0
    if hasattr(dut, "ready_i"):
        dut.ready_i.value = 1
    for p in ("gx_i", "gy_i", "gz_i", "r_i", "g_i", "b_i"):
        if hasattr(dut, p):
            getattr(dut, p).value = 0
    for _ in range(3):
        await RisingEdge(dut.clk_i)
    dut.rst_ni.value = 1
    await RisingEdge(dut.clk_i)
    return bus or Bus(dut, kind)


def field(reg, name, value):
    lsb, bits, _ = reg[2][name]
    return (value >> lsb) & ((1 << bits) - 1)


@cocotb.test()
async def registers(dut):
    """The identification block is the configuration's; status 0 out of reset; CONTROL reads 0."""
    man, info, regs = design()
    bus = await start(dut, info["kind"])
    for name, reg in regs.REGISTERS.items():
        value, refused = await bus.read(reg[0])
        assert not refused, f"{name}: a read refused"
        for f, (lsb, bits, want) in reg[2].items():
            got = field(reg, f, value)
            if want is not None:
                assert got == want, f"{name}.{f} = {got:#x}, the configuration's is {want:#x}"
            else:
                assert got == 0, f"{name}.{f} = {got:#x} out of reset"
        if reg[1] == "wo":
            assert value == 0, f"{name} reads {value:#x}"
    dut._log.info("registers: %d read, as the configuration's", len(regs.REGISTERS))


@cocotb.test()
async def refusals(dut):
    """Every refused access is an error response, changes nothing, and is counted."""
    man, info, regs = design()
    bus = await start(dut, info["kind"])
    R = regs.REGISTERS
    used = {r[0] for r in R.values()}
    hole = max(o for o in range(0, regs.WINDOW_OFFSET, 4) if o not in used)
    cases = [
        ("read of an address no register has", bus.read(hole)),
        ("write to an address no register has", bus.write(hole, 0xFFFFFFFF)),
        ("write to a read-only register", bus.write(R["ID"][0], 0)),
        ("read of a window", bus.read(regs.WINDOW_OFFSET)),
        ("partial write", bus.write(R["CONTROL"][0], 1 << R["CONTROL"][2]["SWAP"][0], 0x1)),
    ]
    if "TABLE" not in regs.WINDOWS:
        cases.append(("table write of a design without a loaded table",
                      bus.write(regs.WINDOW_OFFSET + 3 * regs.AXIS_STRIDE, 0)))
    for what, access in cases:
        r = await access
        refused = r[1] if isinstance(r, tuple) else r
        assert refused, f"a {what} was answered OK"
    errors, _ = await bus.read(R["ERRORS"][0])
    assert field(R["ERRORS"], "COUNT", errors) == len(cases), f"ERRORS = {errors}, want {len(cases)}"
    # Nothing changed: the magic is the magic, no swap was requested by the partial write.
    magic, _ = await bus.read(R["ID"][0])
    assert magic == regs.MAGIC
    status, _ = await bus.read(R["STATUS"][0])
    assert status == 0, f"STATUS = {status:#x} after the refusals"
    refused = await bus.write(R["CONTROL"][0], 1 << R["CONTROL"][2]["CLEAR_ERRORS"][0])
    assert not refused
    errors, _ = await bus.read(R["ERRORS"][0])
    assert errors == 0, f"ERRORS = {errors} after CONTROL.CLEAR_ERRORS"
    dut._log.info("refusals: %d refused and counted", len(cases))


def read_vectors(man, info):
    fields = info["vector_fields"]
    out = []
    with open(info["vectors"]) as f:
        for line in f:
            v = [int(x, 16) for x in line.split()]
            out.append(dict(zip(fields, v)))
    return out


@cocotb.test()
async def frame(dut):
    """Maps written during a frame, a swap requested inside it, samples in flight at the swap."""
    man, info, regs = design()
    bus = await start(dut, info["kind"])
    R = regs.REGISTERS
    rng = random.Random(SEED)
    handshake = hasattr(dut, "ready_i")
    vectors = read_vectors(man, info)
    limit = int(os.environ.get("RMAP_LIMIT", "0"))
    parts = [[v for v in vectors if v["map"] == k] for k in (0, 1)]
    if limit:
        parts = [p[:limit] for p in parts]
    # Each field's port: <field>_i for an input, <field>_o (or the field itself) for an output.
    ports = {p["name"]: p["dir"] for p in man["modules"][0]["ports"]}
    port = {}
    for f in info["vector_fields"]:
        for p in (f, f + "_i", f + "_o"):
            if p in ports:
                port[f] = p
                break
    ins = [f for f in port if ports[port[f]] == "input"]
    outs = [f for f in port if ports[port[f]] == "output"]
    if os.environ.get("RMAP_PLANT") == "expected":
        parts[1][len(parts[1]) // 2][outs[-1]] ^= 1
    expected = parts[0] + parts[1]
    clock = 0
    got = []
    delivered_at = []  # the clock of each result
    state = {"hold_last": True, "sent": 0}

    async def clocks():
        nonlocal clock
        while True:
            await RisingEdge(dut.clk_i)
            clock += 1

    # Inputs are driven and outputs sampled at the falling edge, as the Verilog testbenches do:
    # what is seen there holds at the coming rising edge.
    async def sink():
        while len(got) < len(expected):
            await FallingEdge(dut.clk_i)
            # ready_i for the coming edge (a value written here reads back only after it).
            ready = not handshake or rng.random() >= 0.25
            if handshake:
                dut.ready_i.value = int(ready)
            if dut.valid_o.value == 1 and ready:
                got.append({f: int(getattr(dut, port[f]).value) for f in outs})
                delivered_at.append(clock)

    async def source(part, release):
        """One frame: the samples of `part`, the last with last_i; `release()` gates the last
        sample. A presented sample stays until it is accepted (ready_o at the edge)."""
        k = 0
        will = False  # the sample presented is accepted at the coming edge
        while True:
            await FallingEdge(dut.clk_i)
            if will:
                k += 1
                state["sent"] += 1
            if dut.valid_i.value == 1 and not will:
                pass  # held: not accepted yet
            elif k == len(part) or (k == len(part) - 1 and not release()) or rng.random() < 0.3:
                dut.valid_i.value = 0
                dut.last_i.value = 0
                will = False
                if k == len(part):
                    return
                continue
            else:
                for f in ins:
                    getattr(dut, port[f]).value = part[k][f]
                dut.last_i.value = int(k == len(part) - 1)
                dut.valid_i.value = 1
            will = not handshake or dut.ready_o.value == 1

    cocotb.start_soon(clocks())
    sink_task = cocotb.start_soon(sink())
    swap_seen_pending = {"v": False}
    frame_a = cocotb.start_soon(source(parts[0], lambda: swap_seen_pending["v"]))

    # The second map (and table), written back to back during the frame: every window from
    # its file map2_<x|y|z|table>.hex.
    map2 = {}
    for name in regs.WINDOWS:
        stem = name.lower().removeprefix("map_")
        f = next(Path(".").glob(f"*map2_{stem}.hex"))
        map2[name] = [int(l, 16) for l in f.read_text().splitlines()
                      if l.strip() and not l.startswith("//")]
    t0 = clock
    for name, (axis, offset, entries, bits) in regs.WINDOWS.items():
        assert len(map2[name]) == entries, f"{name}: {len(map2[name])} entries in its file"
        for k, value in enumerate(map2[name]):
            refused = await bus.write(offset + 4 * k, value)
            assert not refused, f"{name} entry {k} refused"
    n = sum(len(m) for m in map2.values())
    per = (clock - t0) / n
    dut._log.info("frame: %d map writes in %d clocks (%.2f clocks a write; the slave's least: %d)",
                  n, clock - t0, per, info["clocks_per_access"])
    assert per >= info["clocks_per_access"], "faster than the slave can answer"
    # The swap, requested inside the frame: pending until its last sample.
    assert state["sent"] < len(parts[0]), "the frame ended before the maps were written (RMAP_LIMIT too small?)"
    assert not await bus.write(R["CONTROL"][0], 1 << R["CONTROL"][2]["SWAP"][0])
    for _ in range(3):
        status, _ = await bus.read(R["STATUS"][0])
        assert field(R["STATUS"], "SWAP_PENDING", status) == 1, "the swap did not wait for the frame's end"
        frames, _ = await bus.read(R["FRAMES"][0])
        assert frames == 0, "a swap inside the frame"
    swap_seen_pending["v"] = True
    await frame_a
    # A window write right after the swap waits until the samples accepted before it have left.
    refused = await bus.write(regs.WINDOWS["MAP_X"][1], map2["MAP_X"][0])
    wrote_at = clock
    assert not refused
    frames, _ = await bus.read(R["FRAMES"][0])
    assert frames == 1, f"FRAMES = {frames} after the swap"
    assert len(delivered_at) >= len(parts[0]) and delivered_at[len(parts[0]) - 1] <= wrote_at, (
        f"a window write was answered at clock {wrote_at}, before the samples accepted before "
        f"the swap had left ({len(delivered_at)} of {len(parts[0])} delivered"
        + (f", the last at {delivered_at[len(parts[0]) - 1]})" if len(delivered_at) >= len(parts[0]) else ")"))
    await source(parts[1], lambda: True)
    await sink_task
    bad = [(k, e, g) for k, (e, g) in enumerate(zip(expected, got))
           if any(e[f] != g[f] for f in outs)]
    for k, e, g in bad[:5]:
        dut._log.error("sample %d: expected %s, got %s", k, {f: e[f] for f in outs}, g)
    dut._log.info("%d passed, %d failed", len(expected) - len(bad), len(bad))
    assert not bad, f"{len(bad)} of {len(expected)} results differ from the model's"
