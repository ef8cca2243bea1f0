{% extends "tb/base_tb.v" %}
{%- block description %}
//
// {= t.module =}: {= inner =} behind {% if wishbone %}a Wishbone{% else %}an AXI4-Lite{% endif %} slave. Everything the host does goes
// through the bus, as a CPU would do it. First the register checks: every register of the
// identification block read and compared with the configuration (src/stages/rmap_regs/
// regmap.rs), the status registers' values out of reset, and the refusals (a write to a
// read-only register, an address no register has, a read of a window, a partial write{% if !table %}, a
// write to the table window of a design without a loaded table{% endif %}) each answered with an
// error and counted in ERRORS, which CONTROL.CLEAR_ERRORS clears. Then the vectors come in two
// parts: `map` 0, shaded with the scene's map the design holds from reset, then `map` 1, shaded
// with the second map. While the map-0 part streams, this testbench writes map2_<axis>.hex
// into the map windows (one word per entry, a bus access begun three clocks in four); the
// first map-1 vector waits until the load is complete, CONTROL.SWAP is written, STATUS shows
// the swap done and FRAMES counts it. Every sample is its frame's last (last_i high), so the
// swap happens at the first clock after it is requested. The mid-stream reset comes before the
// swap and abandons the bus access in progress, which is begun again.
{%- endblock %}
{%- block decls %}

  // The second map (map2_<axis>.hex, logical address order), written through the windows.
  localparam MAP_ENTRIES = {= t.map_entries =};  // per axis, 2^A
  localparam A           = {= t.map_addr_bits =};  // logical map address bits
{%- if t.table_entries > 0 %}
  localparam TABLE_ENTRIES = {= t.table_entries =};  // the compensation table, 2^F, after the maps (axis slot 3)
  localparam NWRITES     = {= t.nwrites =};  // all three axis maps and the table
{%- else %}
  localparam NWRITES     = {= t.nwrites =};  // all three axis maps
{%- endif %}
  reg [{= t.map_bits - 1 =}:0] map2 [0:NWRITES-1];
  integer     nwr;  // map writes done
  reg [A+1:0] wi;
  reg swapped;  // the swap has been seen on the bus

  // ---------------------------------------------------------------- the bus
  localparam WB         = {= w =};  // word address bits
  localparam WINDOW     = {= window_word =};  // word address of the windows
  localparam NCHECKS    = {= checks.len() =};
  localparam STATUS     = {= status_word =};
  localparam FRAMES     = {= frames_word =};
  localparam CONTROL    = {= control_word =};
  localparam [31:0] SWAP         = 32'h{= "{:x}"|format(swap_mask) =};
  localparam [31:0] SWAP_PENDING = 32'h{= "{:x}"|format(pending_mask) =};
  localparam POLLS      = 1000;  // STATUS reads before the swap counts as lost
  localparam BUS_WAIT   = 4 * TIMEOUT;  // clocks an access may wait for its answer
  // The register checks, in order: a write or a read, its word address, data and byte
  // enables, whether it must be refused, and the read data expected under a mask.
  reg          c_we [0:NCHECKS-1];
  reg [WB-1:0] c_adr [0:NCHECKS-1];
  reg [31:0]   c_dat [0:NCHECKS-1];
  reg [3:0]    c_be [0:NCHECKS-1];
  reg          c_err [0:NCHECKS-1];
  reg [31:0]   c_exp [0:NCHECKS-1];
  reg [31:0]   c_mask [0:NCHECKS-1];
  integer      chk;  // checks done
  // The access in progress (op_*), and what ended it.
  reg          op_active, op_we, op_err, got_err;
  reg [WB-1:0] op_adr;
  reg [31:0]   op_dat, got_dat;
  reg [3:0]    op_be;
  reg [2:0]    op_kind;  // 0 a check, 1 a map write, 2 the swap request, 3 a STATUS poll, 4 FRAMES
  reg          want_swap, swap_asked, swap_seen;
  integer      polls;
  integer      op_clocks;  // clocks the access in progress has waited
{%- if !wishbone %}
  reg [1:0]    ax_phase;  // 0 address offered, 1 taken at the last edge, 2 awaiting the response
{%- endif %}

  // Offers an access on the bus.
  task bus_start;
    input          we;
    input [WB-1:0] adr;
    input [31:0]   dat;
    input [3:0]    be;
    begin
      op_active = 1'b1;
      op_clocks = 0;
      op_we = we;
      op_adr = adr;
      op_dat = dat;
      op_be = be;
{%- if wishbone %}
      wb_cyc_i = 1'b1;
      wb_stb_i = 1'b1;
      wb_we_i = we;
      wb_adr_i = adr;
      wb_dat_i = dat;
      wb_sel_i = be;
{%- else %}
      ax_phase = 2'd0;
      if (we) begin
        s_axil_awvalid = 1'b1;
        s_axil_awaddr = {adr, 2'b00};
        s_axil_wvalid = 1'b1;
        s_axil_wdata = dat;
        s_axil_wstrb = be;
      end else begin
        s_axil_arvalid = 1'b1;
        s_axil_araddr = {adr, 2'b00};
      end
{%- endif %}
    end
  endtask

  // Withdraws every request (the end of an access, or a reset under one).
  task bus_idle;
    begin
      op_active = 1'b0;
{%- if wishbone %}
      wb_cyc_i = 1'b0;
      wb_stb_i = 1'b0;
{%- else %}
      s_axil_awvalid = 1'b0;
      s_axil_wvalid = 1'b0;
      s_axil_arvalid = 1'b0;
      ax_phase = 2'd0;
{%- endif %}
    end
  endtask

  // One clock of the bus (at the falling edge): ends the access in progress when its answer
  // is here (returns 1 in `ended`, with got_err and got_dat).
  reg ended;
  task bus_clock;
    begin
      ended = 1'b0;
      if (op_active) begin
        op_clocks = op_clocks + 1;
        if (op_clocks > BUS_WAIT)
          $fatal(1, "a bus access not answered in %0d clocks: %0s word %0d", BUS_WAIT, op_we ? "write" : "read", op_adr);
      end
{%- if wishbone %}
      if (wb_ack_o === 1'b1 && wb_err_o === 1'b1) protocol_error("wb_ack_o and wb_err_o together");
      if (!op_active && (wb_ack_o !== 1'b0 || wb_err_o !== 1'b0)) protocol_error("wb_ack_o or wb_err_o without an access");
      if (op_active && (wb_ack_o === 1'b1 || wb_err_o === 1'b1)) begin
        got_err = wb_err_o;
        got_dat = wb_dat_o;
        ended = 1'b1;
        bus_idle;
      end
{%- else %}
      if (!op_active && (s_axil_bvalid !== 1'b0 || s_axil_rvalid !== 1'b0)) protocol_error("a response without an access");
      if (op_active) begin
        if (ax_phase == 2'd1) begin
          // Taken at the last edge: the request is withdrawn, the response awaited.
          s_axil_awvalid = 1'b0;
          s_axil_wvalid = 1'b0;
          s_axil_arvalid = 1'b0;
          ax_phase = 2'd2;
        end
        if (ax_phase == 2'd0) begin
          if (op_we && (s_axil_awready === 1'b1) != (s_axil_wready === 1'b1)) protocol_error("awready without wready");
          if (op_we ? s_axil_awready === 1'b1 : s_axil_arready === 1'b1) ax_phase = 2'd1;
        end else if (ax_phase == 2'd2) begin
          if (op_we ? s_axil_bvalid === 1'b1 : s_axil_rvalid === 1'b1) begin
            got_err = op_we ? s_axil_bresp == 2'b10 : s_axil_rresp == 2'b10;
            if ((op_we ? s_axil_bresp : s_axil_rresp) == 2'b01 || (op_we ? s_axil_bresp : s_axil_rresp) == 2'b11)
              protocol_error("a response neither OKAY nor SLVERR");
            got_dat = s_axil_rdata;
            ended = 1'b1;
            bus_idle;
          end
        end
      end
{%- endif %}
    end
  endtask

  // Ends the access and begins the next one: the register checks, then (when `writes` allows)
  // the map writes, then the swap.
  task host_clock;
    input writes;
    begin
      bus_clock;
      if (ended) begin
        case (op_kind)
          3'd0: begin
            if (got_err !== c_err[chk] || (!op_we && !got_err && (got_dat & c_mask[chk]) !== c_exp[chk])) begin
              $display("REGISTER check %0d: %0s word %0d: %0s, read %h, expected %0s %h under %h", chk,
                       op_we ? "write" : "read", op_adr, got_err ? "refused" : "answered", got_dat,
                       c_err[chk] ? "refused" : "answered", c_exp[chk], c_mask[chk]);
              errors = errors + 1;
            end
            chk = chk + 1;
          end
          3'd1: begin
            if (got_err) protocol_error("a map write refused");
            nwr = nwr + 1;
          end
          3'd2: begin
            if (got_err) protocol_error("CONTROL.SWAP refused");
            swap_asked = 1'b1;
          end
          3'd3: begin
            polls = polls + 1;
            if (polls > POLLS) $fatal(1, "the swap did not happen: STATUS %h after %0d reads", got_dat, POLLS);
            if ((got_dat & SWAP_PENDING) == 32'd0) swap_seen = 1'b1;
          end
          default: begin
            if (got_dat !== 32'd1) protocol_error("FRAMES is not 1 after the swap");
            swapped = 1'b1;
            $display("swap with line %0d, after %0d map writes and %0d STATUS reads", v_line[nin[DL-1:0]], nwr, polls);
          end
        endcase
      end
      if (!op_active) begin
        rnd = $random(seed);
        if (chk < NCHECKS) begin
          op_kind = 3'd0;
          bus_start(c_we[chk], c_adr[chk], c_dat[chk], c_be[chk]);
        end else if (nwr < NWRITES) begin
          if (writes && rnd[1:0] != 2'b00) begin
            wi = nwr[A+1:0];
            op_kind = 3'd1;
            bus_start(1'b1, WINDOW + wi, {{= 32 - t.map_bits =}'d0, map2[wi]}, 4'hf);
          end
        end else if (want_swap && !swap_asked) begin
          op_kind = 3'd2;
          bus_start(1'b1, CONTROL[WB-1:0], SWAP, 4'hf);
        end else if (swap_asked && !swap_seen) begin
          op_kind = 3'd3;
          bus_start(1'b0, STATUS[WB-1:0], 32'd0, 4'hf);
        end else if (swap_seen && !swapped) begin
          op_kind = 3'd4;
          bus_start(1'b0, FRAMES[WB-1:0], 32'd0, 4'hf);
        end
      end
    end
  endtask
{%- endblock %}
{%- block init %}
{%- include "tb/map2_init.v" %}
    swapped = 1'b0;
    last_i = 1'b1;
    chk = 0;
    op_active = 1'b0;
    op_kind = 3'd0;
    want_swap = 1'b0;
    swap_asked = 1'b0;
    swap_seen = 1'b0;
    polls = 0;
    got_err = 1'b0;
    got_dat = 32'd0;
{%- if !wishbone %}
    ax_phase = 2'd0;
    s_axil_bready = 1'b1;
    s_axil_rready = 1'b1;
{%- endif %}
{%- for c in checks %}
    c_we[{= loop.index0 =}] = 1'b{= c.we as u8 =}; c_adr[{= loop.index0 =}] = {= w =}'d{= c.word =}; c_dat[{= loop.index0 =}] = 32'h{= "{:x}"|format(c.data) =}; c_be[{= loop.index0 =}] = 4'h{= "{:x}"|format(c.be) =};
    c_err[{= loop.index0 =}] = 1'b{= c.err as u8 =}; c_exp[{= loop.index0 =}] = 32'h{= "{:x}"|format(c.expect) =}; c_mask[{= loop.index0 =}] = 32'h{= "{:x}"|format(c.mask) =};  // {= c.what =}
{%- endfor %}
{%- endblock %}
{%- block preload %}

    // The register checks, before any sample.
    while (chk < NCHECKS) begin
      @(negedge clk_i);
      if (valid_o !== 1'b0) protocol_error("valid_o during the register checks");
      host_clock(1'b0);
    end
{%- endblock %}
{%- block reset_quiet %}
        if (swapped) $fatal(1, "the mid-stream reset must come before the swap");
        bus_idle;  // the access in progress is lost and begun again
{%- endblock %}
{%- block hold %}

      // The first map-1 vector waits for the second map and the swap.
      if (present && !swapped && v_map[nin[DL-1:0]] == 1'b1) begin
        present = 1'b0;
        if (nwr == NWRITES) want_swap = 1'b1;
      end
{%- endblock %}
{%- block accept %}
          if (v_map[si] == 1'b1 && !swapped) begin
            $fatal(1, "%0s line %0d: a map-1 vector before the swap", vector_file, v_line[si]);
          end
          if (v_map[si] == 1'b0 && swapped) begin
            $fatal(1, "%0s line %0d: a map-0 vector after the swap", vector_file, v_line[si]);
          end
{%- endblock %}
{%- block host %}

      // The host, on the bus.
      host_clock(1'b1);
{%- endblock %}
{%- block finish %}
    if (!swapped) protocol_error("no map-1 vector: the buffer swap was not tested");
    if (chk != NCHECKS) protocol_error("the register checks did not all run");
{%- endblock %}
