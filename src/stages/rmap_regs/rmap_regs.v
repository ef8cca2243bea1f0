{= h.header =}
`default_nettype none

// Register block of the bus slave (docs/SOC.md; the map: rmapgen::stages::rmap_regs::regmap,
// which every view is generated from). One access at a time on a plain register port: an
// access presented with req_i (held, with we_i, addr_i, wdata_i and be_i, until ack_o) is
// answered by ack_o for one clock, with err_o when it is refused and rdata_o for a read.
// A read or a register write is answered at the first clock after it is presented; a window
// write waits while a swap is pending or samples accepted before the last swap are still in
// the pipeline ({= top =}'s swap and write rules), then is written through the host write
// port (one entry, wr_en_o high one clock) and answered.
//
// Word addresses (addr_i = byte offset / 4):{% for r in m.regs %}
//   {= "{:#06x}"|format(r.offset) =} {= r.name =} ({= r.access.name() =}){% endfor %}
//   {= "{:#06x}"|format(m.window_base) =} the windows: word (axis << {= a =}) | entry of the upper half,{% for w in m.windows %}
//          {= w.name =} axis {= w.axis =}, {= w.entries =} entries of {= w.bits =} bits{% endfor %}
// Refused (err_o, counted in ERRORS, saturating; nothing changes): an address no register or
// window entry has, a write to a read-only register, a read of a window, a write whose byte
// enables are not all set.
//
// Frames: the sample stream's accepted beats (accept_i) carry the frame's last flag (last_i).
// CONTROL.SWAP sets SWAP_PENDING; swap_o is high for one clock at the first clock that is not
// inside a frame (after a last beat, or before any beat), so the beat accepted with it, the
// first of the next frame, reads the new front buffer. A constant last_i of 1 swaps at the
// next clock. FRAMES counts the swaps.
module {= h.module =} (
{= h.ports =}
);

  // Register word addresses.
{%- for r in m.regs %}
  localparam [{= w - 1 =}:0] {= r.name =} = {= w =}'d{= r.word() =};
{%- endfor %}

  // ---- Decode
  wire              win     = addr_i[{= w - 1 =}];          // the windows: the upper half
  wire [1:0]        axis    = addr_i[{= a + 1 =}:{= a =}];
  wire [{= a - 1 =}:0]        entry   = addr_i[{= a - 1 =}:0];
  wire              full    = &be_i;
  // A window entry a write may reach: the three axis maps{% if table %}, and the table's entries{% endif %}
  // (the fourth axis slot{% if table %} past them{% endif %} is no memory's).
  wire              win_ok  = {= win_ok =};

  reg  [31:0]       rdata;
  reg               reg_ok;   // a register of the map
  reg               reg_wr;   // ... that takes writes
  always @* begin
    rdata  = 32'd0;
    reg_ok = 1'b0;
    reg_wr = 1'b0;
    if (!win) begin
      case (addr_i)
{%- for r in m.regs %}
        {= r.name =}: begin
          reg_ok = 1'b1;
{%- if r.access.name() == "WO" %}
          reg_wr = 1'b1;
{%- endif %}
          rdata  = {= r.read_expr() =};
        end
{%- endfor %}
        default: ;
      endcase
    end
  end

  // ---- The access
  reg               ack_q, err_q, ack_we_q;
  reg  [31:0]       rdata_q;
  reg               pending_q, in_frame_q;
  reg  [{= iw - 1 =}:0]        inflight_q, drain_q;
  reg  [31:0]       frames_q;
  reg  [15:0]       errors_q;
  reg               wr_en_q;
  reg  [1:0]        wr_axis_q;
  reg  [{= a - 1 =}:0]        wr_addr_q;
  reg  [{= mb - 1 =}:0]        wr_data_q;

  wire draining = drain_q != {= iw =}'d0;
  wire swap     = pending_q && !in_frame_q && !wr_en_q;
  wire take     = req_i && !ack_q;                  // an access presented, not yet answered
  wire win_wait = draining || pending_q;            // a window write waits for these
  wire bad      = we_i ? !(full && (win_ok || (reg_ok && reg_wr))) : (win || !reg_ok);
  wire done     = take && (bad || !we_i || !win || !win_wait);
  wire win_wr   = done && !bad && we_i && win;
  wire ctl_wr   = done && !bad && we_i && !win && addr_i == CONTROL;
  wire swap_req     = ctl_wr && wdata_i[{= swap_bit =}];
  wire clear_errors = ctl_wr && wdata_i[{= clear_bit =}];

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      ack_q      <= 1'b0;
      err_q      <= 1'b0;
      ack_we_q   <= 1'b0;
      pending_q  <= 1'b0;
      in_frame_q <= 1'b0;
      inflight_q <= {= iw =}'d0;
      drain_q    <= {= iw =}'d0;
      frames_q   <= 32'd0;
      errors_q   <= 16'd0;
      wr_en_q    <= 1'b0;
    end else begin
      ack_q    <= done;
      err_q    <= done && bad;
      if (done)
        ack_we_q <= we_i;
      wr_en_q  <= win_wr;
      if (swap_req)
        pending_q <= 1'b1;
      else if (swap)
        pending_q <= 1'b0;
      if (accept_i)
        in_frame_q <= !last_i;
      inflight_q <= inflight_q + {{= iw - 1 =}'d0, accept_i} - {{= iw - 1 =}'d0, deliver_i};
      // At the swap: the beats accepted before it (not the one accepted with it) must leave
      // before the old front buffer is written.
      if (swap)
        drain_q <= inflight_q - {{= iw - 1 =}'d0, deliver_i};
      else if (draining && deliver_i)
        drain_q <= drain_q - {= iw =}'d1;
      if (swap)
        frames_q <= frames_q + 32'd1;
      if (clear_errors)
        errors_q <= 16'd0;
      else if (done && bad && errors_q != 16'hffff)
        errors_q <= errors_q + 16'd1;
    end
  end

  // Data registers: not reset.
  always @(posedge clk_i) begin
    if (done)
      rdata_q <= rdata;
    if (win_wr) begin
      wr_axis_q <= axis;
      wr_addr_q <= entry;
      wr_data_q <= wdata_i[{= mb - 1 =}:0];
    end
  end

  assign ack_o     = ack_q;
  assign err_o     = err_q;
  assign ack_we_o  = ack_we_q;
  assign rdata_o   = rdata_q;
  assign wr_en_o   = wr_en_q;
  assign wr_axis_o = wr_axis_q;
  assign wr_addr_o = wr_addr_q;
  assign wr_data_o = wr_data_q;
  assign swap_o    = swap;

  // Data bits no register or window takes.
  wire unused_wdata = ^wdata_i[31:{= mb =}];

endmodule

`default_nettype wire
