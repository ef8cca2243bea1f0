// Formal harness of the handshake top (rmapgen generate --handshake --axis): SymbiYosys proves
// its assertions by k-induction (formal/run_formal.py writes the .sby, sets the parameters
// from the generated rmap_top.v and connects the probes p_* to the top's internal signals).
//
// Samples are tagged: sample n (the n-th accepted, from 0 after reset) carries side_i = n mod
// 2^SD, which the top passes to side_o with its result. The harness keeps its own model of the
// documented behaviour (accepted and left counts, the front buffer after each swap, the front
// buffer each tag was accepted with) and asserts:
//   a_order    a result leaves (valid_o && ready_i) with the tag of the oldest sample not yet
//              left: none lost, duplicated or reordered; a_fly: valid_o only with one in flight
//   a_hold     valid_o && !ready_i at an edge: valid_o, zero_o, i_o and side_o unchanged after it
//   a_rdy_*    ready_o: low in reset, high at the first edge after it, high after any edge
//              without a stall (!valid_o || ready_i), that is low only after a stall, and it
//              is the pipeline's clock enable register (ready_i reaches it only through a clock)
//   a_rd_buf   the sample entering map_lookup reads the front buffer of its acceptance edge
//              (swap_i in that clock included); a_wr_buf: host writes go to the back buffer
//   a_live     bounded response: after LAT + 1 edges in a row with ready_i high, the samples in
//              flight are exactly those accepted at the last LAT edges (LAT: the manifest's
//              documented latency), so every sample leaves LAT edges after its acceptance
//              while ready_i stays high; with a_order, none is ever stuck
// rst_ni is free after the first clock: a reset in the middle of the stream must leave nothing
// in flight (a_rdy_reset) and restart the tags at 0.
// inv_* are the inductive invariants (the queue and the pipeline hold the samples in flight in
// order; the front register is the model's); they are proven like the others.
`default_nettype none

module rmap_formal #(
  parameter G    = 12,  // gradient width
  parameter WA   = 9,   // wr_addr_i width
  parameter M    = 8,   // intensity and map entry width
  parameter SD   = 5,   // side_i width: the tag
  parameter L    = 23,  // pipeline length, accept to the output register (SIDE_DELAY)
  parameter BUFD = 12,  // accept to map_lookup's input (BUF_DELAY)
  parameter FW   = 6,   // width of the in-flight count: 2^FW > L + 2
  parameter LAT  = 24,  // documented latency, accept to valid_o (the manifest's "latency")
  parameter INV  = 1    // 1: assert the inductive invariants inv_* too (the proof); 0: only the
                        // properties (a bounded search for a planted fault reports those)
) (
  input wire          clk_i,
  input wire          rst_ni,
  input wire          valid_i,
  input wire [G-1:0]  gx_i,
  input wire [G-1:0]  gy_i,
  input wire [G-1:0]  gz_i,
  input wire          swap_i,
  input wire          wr_en_i,
  input wire [1:0]    wr_axis_i,
  input wire [WA-1:0] wr_addr_i,
  input wire [M-1:0]  wr_data_i,
  input wire          ready_i
);

  // Probes, connected to the top's internal signals by the .sby script (connect -set).
  wire [L-1:0]    p_v;      // the stages' valid bits, bit 0 newest
  wire [L*SD-1:0] p_s;      // u_side_delay's line, newest in the low SD bits
  wire [BUFD-1:0] p_b;      // u_buf_delay's line
  wire            p_rd;     // map_lookup's rd_buf_i
  wire            p_wrbuf;  // map_lookup's wr_buf_i
  wire            p_front;  // the front-buffer register
  wire            p_head;   // the output queue: head (valid_o) and skid entries
  wire            p_skid;
  wire [SD-1:0]   p_skid_s;
  wire            p_en;     // every stage's clock enable

  reg  [SD-1:0] in_q, out_q;  // tags of the next sample accepted and of the next to leave
  reg  [FW-1:0] fly_q;        // accepted and not left
  reg           front_q;      // the documented front buffer
  reg  [(1<<SD)-1:0] rec_q;   // front buffer each tag was accepted with

  wire          ready_o, valid_o, zero_o;
  wire [M-1:0]  i_o;
  wire [SD-1:0] side_o;
  wire          acc = valid_i && ready_o;
  wire          pop = valid_o && ready_i;
  wire          front_d = front_q ^ swap_i;

  rmap_top u_dut (
    .clk_i     (clk_i),
    .rst_ni    (rst_ni),
    .valid_i   (valid_i),
    .gx_i      (gx_i),
    .gy_i      (gy_i),
    .gz_i      (gz_i),
    .swap_i    (swap_i),
    .wr_en_i   (wr_en_i),
    .wr_axis_i (wr_axis_i),
    .wr_addr_i (wr_addr_i),
    .wr_data_i (wr_data_i),
    .side_i    (in_q),
    .ready_i   (ready_i),
    .ready_o   (ready_o),
    .valid_o   (valid_o),
    .zero_o    (zero_o),
    .i_o       (i_o),
    .side_o    (side_o)
  );

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      in_q    <= {SD{1'b0}};
      out_q   <= {SD{1'b0}};
      fly_q   <= {FW{1'b0}};
      front_q <= 1'b0;
    end else begin
      if (acc) in_q <= in_q + 1'b1;
      if (pop) out_q <= out_q + 1'b1;
      fly_q   <= fly_q + {{FW-1{1'b0}}, acc} - {{FW-1{1'b0}}, pop};
      front_q <= front_d;
    end
  end

  always @(posedge clk_i) begin
    if (acc) rec_q[in_q] <= front_d;
  end

  // Reset in the first clock, and at any clock after it (documented to drop the samples in
  // flight: a_rdy_reset says nothing is left of them).
  reg init_q = 1'b1;
  always @(posedge clk_i) begin
    init_q <= 1'b0;
  end
  always @* begin
    if (init_q) assume (!rst_ni);
  end

  // Bounded response: hi_q counts the edges in a row with ready_i high (saturating at LAT + 1),
  // acc_h_q records which of the last LAT edges accepted a sample (bit 0 the last edge).
  reg [FW-1:0]  hi_q;
  reg [LAT-1:0] acc_h_q;
  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      hi_q    <= {FW{1'b0}};
      acc_h_q <= {LAT{1'b0}};
    end else begin
      hi_q    <= !ready_i ? {FW{1'b0}} : (hi_q > LAT ? hi_q : hi_q + 1'b1);
      acc_h_q <= {acc_h_q[LAT-2:0], acc};
    end
  end
  reg [FW-1:0] recent;  // samples accepted at the last LAT edges
  reg          live_v_ok;
  integer      j;
  always @* begin
    recent = {FW{1'b0}};
    for (j = 0; j < LAT; j = j + 1) recent = recent + acc_h_q[j];
    // While ready_i has been high, stage k holds the sample accepted k + 1 edges ago (the
    // invariant a_live follows from; the enable is high from the second such edge).
    live_v_ok = 1'b1;
    for (j = 0; j < L; j = j + 1) begin
      if (hi_q >= j + 2 && j < LAT) live_v_ok = live_v_ok && p_v[j] == acc_h_q[j];
    end
  end

  // The samples in flight, oldest first: head, skid, then the pipeline from its end.
  reg          inv_ok;
  reg [FW-1:0] n;
  reg          rd_ok;
  integer      k;
  always @* begin
    inv_ok = 1'b1;
    rd_ok  = 1'b1;
    n      = {FW{1'b0}};
    if (p_head) begin
      inv_ok = inv_ok && side_o == out_q;
      n = n + 1'b1;
    end
    if (p_skid) begin
      inv_ok = inv_ok && p_head && p_skid_s == out_q + n[SD-1:0];
      n = n + 1'b1;
    end
    for (k = L - 1; k >= 0; k = k - 1) begin
      if (p_v[k]) begin
        inv_ok = inv_ok && p_s[k*SD +: SD] == out_q + n[SD-1:0];
        if (k < BUFD) rd_ok = rd_ok && p_b[k] == rec_q[p_s[k*SD +: SD]];
        n = n + 1'b1;
      end
    end
  end

  // rst_ni as it was at the last edge and the one before: with the asynchronous reset in the
  // clock before an edge, that edge left the reset state; the first edge with rst_ni high
  // starts the stream.
  reg          prev_rst_q = 1'b0, prev2_rst_q = 1'b0;
  reg          stall_q;
  reg [M-1:0]  i_q;
  reg          zero_q;
  reg [SD-1:0] side_q;
  always @(posedge clk_i) begin
    prev_rst_q  <= rst_ni;
    prev2_rst_q <= prev_rst_q;
    stall_q     <= valid_o && !ready_i;
    i_q         <= i_o;
    zero_q      <= zero_o;
    side_q      <= side_o;
  end

  always @* begin
    if (!rst_ni || !prev_rst_q) begin
      // In reset, and after the last edge in reset: nothing in flight, ready_o low.
      a_rdy_reset: assert (!ready_o && !valid_o && !p_skid && p_v == {L{1'b0}} && fly_q == {FW{1'b0}});
      if (INV) begin inv_front0:  assert (p_front == front_q && !p_head && in_q == out_q); end
      if (INV) begin inv_live0:   assert (hi_q == {FW{1'b0}} && acc_h_q == {LAT{1'b0}}); end
    end else begin
      if (INV) begin inv_queue:   assert (inv_ok && n == fly_q && in_q == out_q + fly_q[SD-1:0]); end
      if (INV) begin inv_rd:      assert (rd_ok); end
      if (INV) begin inv_front:   assert (p_front == front_q); end
      if (INV) begin inv_en:      assert (p_en == !p_skid); end
      a_fly:       assert (!valid_o || fly_q != {FW{1'b0}});
      a_order:     assert (!pop || side_o == out_q);
      a_rd_buf:    assert (!p_v[BUFD-1] || p_rd == rec_q[p_s[(BUFD-1)*SD +: SD]]);
      a_rdy_en:    assert (ready_o == p_en);
      a_head:      assert (valid_o == p_head);
      if (INV) begin inv_live_q:  assert (hi_q == {FW{1'b0}} || (!p_skid && p_en)); end
      if (INV) begin inv_live_v:  assert (live_v_ok); end
      if (hi_q > LAT) begin
        a_live:      assert (fly_q == recent);
      end
      if (!prev2_rst_q) begin
        a_rdy_first: assert (ready_o);
      end else begin
        a_hold:      assert (!stall_q || (valid_o && i_o == i_q && zero_o == zero_q && side_o == side_q));
        a_rdy_rule:  assert (ready_o || stall_q);
      end
    end
    a_wr_buf: assert (p_wrbuf == !front_d);
  end

endmodule

`default_nettype wire
