"""cocotb test of the AXI4-Stream top (`rmapgen generate --handshake --axis`), with
cocotbext-axi's AxiStreamSource and AxiStreamSink: every sample of the model's vector file of
the top goes in, every result comes out, compared exactly, tuser and tlast included.

Everything about the design is read from the generated directory (the simulator's working
directory, where the $readmemh files are): manifest.json gives the tdata layouts
(rmapgen::stages::rmap_axis::Packing), the tuser width and the vector file and its fields
(docs/ARCHITECTURE.md, "Vector files"). Nothing here restates a width or an offset.

- Samples go in as frames of 1 to 8 beats (tlast on the last beat), each beat one sample with
  a random tuser; the input padding bits of tdata are random (the design must ignore them).
- The source pauses at random; the sink applies random backpressure (tready low one clock in
  four, now and then for up to 63 clocks).
- The `map` 0 samples are shaded with the scene's map. While they stream, the host port writes
  the second map (map2_<axis>.hex) into the back buffer; after the last map-0 sample is
  accepted, swap_i is pulsed and the `map` 1 samples follow.
- The run fails on any wrong, missing or extra beat (values, tuser, or the frame boundaries
  that tlast makes) and when no result comes for TIMEOUT clocks while some are due.

Environment: RMAP_LIMIT=N takes only the first N samples of each map part; RMAP_PLANT=expected
corrupts one expected value (a planted fault the test must report; tb/cocotb/run_axis.py).
"""

import json
import os
import random
from pathlib import Path

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, RisingEdge, Timer
from cocotbext.axi import AxiStreamBus, AxiStreamFrame, AxiStreamSink, AxiStreamSource

TIMEOUT = 2000  # clocks without a result while results are due
SEED = 14


def packing(p):
    """[(field, offset, bits)] of a Packing and the tdata width."""
    return [(s["field"], s["offset"], s["bits"]) for s in p["slots"]], p["bits"]


def pack(slots, values, rng=None, width=0):
    """One tdata word: each field at its offset; padding random when rng is given."""
    word = rng.getrandbits(width) if rng else 0
    for name, off, bits in slots:
        mask = (1 << bits) - 1
        word &= ~(mask << off)
        word |= (values[name] & mask) << off
    return word


def unpack(slots, word):
    return {name: (word >> off) & ((1 << bits) - 1) for name, off, bits in slots}


def read_vectors(path, fields):
    out = []
    with open(path) as f:
        for n, line in enumerate(f, 1):
            parts = line.split()
            if not parts:
                continue
            assert len(parts) == len(fields), f"{path} line {n}: {len(parts)} fields"
            v = {k: int(x, 16) for k, x in zip(fields, parts)}
            v["line"] = n
            out.append(v)
    return out


def backpressure(rng):
    """Sink pause: low tready one clock in four, and now and then up to 63 clocks."""
    while True:
        if rng.randrange(64) == 0:
            for _ in range(rng.randrange(1, 64)):
                yield True
        else:
            yield rng.randrange(4) == 0


def source_pauses(rng):
    """Source pause: a bubble one clock in five, and now and then up to 15 clocks."""
    while True:
        if rng.randrange(100) == 0:
            for _ in range(rng.randrange(1, 16)):
                yield True
        else:
            yield rng.randrange(5) == 0


@cocotb.test()
async def axis_stream_matches_the_model(dut):
    design = Path.cwd()
    man = json.loads((design / "manifest.json").read_text())
    ax = man["axis"]
    s_slots, s_bits = packing(ax["s_tdata"])
    m_slots, m_bits = packing(ax["m_tdata"])
    tuser_bits = ax["tuser_bits"]
    fields = ax["vector_fields"]
    vectors = read_vectors(design / ax["vectors"], fields)
    limit = int(os.environ.get("RMAP_LIMIT", "0"))
    parts = [[v for v in vectors if v["map"] == m] for m in (0, 1)]
    if limit:
        parts = [p[:limit] for p in parts]
    assert parts[0] and parts[1], "the vector file needs samples of both maps"
    out_names = [s[0] for s in m_slots]
    if os.environ.get("RMAP_PLANT") == "expected":
        v = parts[1][len(parts[1]) // 2]
        v["i"] ^= 1
        dut._log.warning("planted fault: expected i of line %d flipped", v["line"])

    rng = random.Random(SEED)
    cfg = man["config"]
    map_addr_bits = len(dut.wr_addr_i)
    map2 = []
    for axis in "xyz":
        name = f"{cfg.get('prefix', '')}map2_{axis}.hex"
        words = [int(t, 16) for line in (design / name).read_text().splitlines()
                 if line and not line.startswith("//") for t in line.split()]
        assert len(words) == 1 << map_addr_bits, f"{name}: {len(words)} entries"
        map2.append(words)

    cocotb.start_soon(Clock(dut.clk_i, 10, unit="ns").start())
    dut.swap_i.value = 0
    dut.wr_en_i.value = 0
    dut.wr_axis_i.value = 0
    dut.wr_addr_i.value = 0
    dut.wr_data_i.value = 0
    dut.rst_ni.value = 0
    source = AxiStreamSource(AxiStreamBus.from_prefix(dut, "s_axis"), dut.clk_i, dut.rst_ni,
                             reset_active_level=False)
    sink = AxiStreamSink(AxiStreamBus.from_prefix(dut, "m_axis"), dut.clk_i, dut.rst_ni,
                         reset_active_level=False)
    for log in (source.log, sink.log):
        log.setLevel("WARNING")
    source.set_pause_generator(source_pauses(random.Random(SEED + 1)))
    sink.set_pause_generator(backpressure(random.Random(SEED + 2)))
    for _ in range(3):
        await RisingEdge(dut.clk_i)
    dut.rst_ni.value = 1

    # Every beat sent, in order: (vector, tuser, tlast).
    sent = []

    async def send(part):
        k = 0
        while k < len(part):
            n = min(rng.randrange(1, 9), len(part) - k)
            data = bytearray()
            users = []
            for j in range(n):
                v = part[k + j]
                word = pack(s_slots, v, rng, s_bits)
                data += word.to_bytes(s_bits // 8, "little")
                u = rng.getrandbits(tuser_bits) if tuser_bits else 0
                users += [u] * (s_bits // 8)
                sent.append((v, u, int(j == n - 1)))
            await source.send(AxiStreamFrame(data, tuser=users if tuser_bits else None))
            k += n

    # Every beat received: (tdata, tuser, tlast), from the sink's frames.
    got = []

    async def receive():
        while True:
            f = await sink.recv()
            lanes = m_bits // 8
            beats = len(f.tdata) // lanes
            for b in range(beats):
                word = int.from_bytes(bytes(f.tdata[b * lanes:(b + 1) * lanes]), "little")
                # The sink compacts a frame's sideband to one int when every byte agrees, and
                # gives None when the bus has no tuser (--axis-user 0).
                if not tuser_bits:
                    u = 0
                elif isinstance(f.tuser, int):
                    u = f.tuser
                else:
                    u = f.tuser[b * lanes]
                got.append((word, u, int(b == beats - 1)))

    writes_done = cocotb.triggers.Event()

    async def host():
        """The second map into the back buffer, three clocks in four."""
        for axis in range(3):
            for addr, word in enumerate(map2[axis]):
                while True:
                    await FallingEdge(dut.clk_i)
                    if rng.randrange(4):
                        break
                    dut.wr_en_i.value = 0
                dut.wr_en_i.value = 1
                dut.wr_axis_i.value = axis
                dut.wr_addr_i.value = addr
                dut.wr_data_i.value = word
        await FallingEdge(dut.clk_i)
        dut.wr_en_i.value = 0
        writes_done.set()

    cocotb.start_soon(receive())
    cocotb.start_soon(host())
    await send(parts[0])
    await source.wait()  # every map-0 sample accepted
    await writes_done.wait()
    await FallingEdge(dut.clk_i)
    dut.swap_i.value = 1
    await FallingEdge(dut.clk_i)
    dut.swap_i.value = 0
    await send(parts[1])

    idle = 0
    while len(got) < len(sent) and idle < TIMEOUT:
        before = len(got)
        await RisingEdge(dut.clk_i)
        idle = 0 if len(got) > before else idle + 1
    for _ in range(100):  # nothing more may come
        await RisingEdge(dut.clk_i)
    await Timer(1, unit="ns")

    failed = 0
    for k, (v, u, last) in enumerate(sent):
        if k >= len(got):
            break
        word, gu, glast = got[k]
        want = pack(m_slots, v)
        if (word, gu, glast) != (want, u, last):
            failed += 1
            if failed <= 10:
                g = unpack(m_slots, word)
                dut._log.error(
                    "MISMATCH beat %d (vector line %d): expected %s tuser %x tlast %d, got %s tuser %x tlast %d",
                    k, v["line"], {n: hex(v[n]) for n in out_names}, u, last,
                    {n: hex(g[n]) for n in out_names}, gu, glast)
    missing = len(sent) - min(len(sent), len(got))
    extra = len(got) - min(len(sent), len(got))
    passed = len(sent) - failed - missing
    dut._log.info("%d beats sent, %d received", len(sent), len(got))
    if missing:
        dut._log.error("%d results missing (none for %d clocks)", missing, TIMEOUT)
    if extra:
        dut._log.error("%d results more than samples", extra)
    print(f"{passed} passed, {failed + missing + extra} failed", flush=True)
    assert failed == 0 and missing == 0 and extra == 0, (
        f"{failed} wrong, {missing} missing, {extra} extra of {len(sent)} samples")
