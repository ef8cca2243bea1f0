// Formal harness of the handshake top (rmapgen generate --handshake --axis): SymbiYosys proves
// its assertions by k-induction, one run per assertion group (CHK, below); formal/run_formal.py
// writes the .sby, sets the parameters from the generated rmap_top.v and connects the probes
// p_* to the top's internal signals.
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
//   a_tbl_rd_buf, a_tbl_wr_buf  the same for the compensation table when it is a loaded RAM
//              (comp_table = ram, TBUFD > 0): the sample entering atan_rom reads the table of
//              its acceptance edge's front buffer, and host writes go to its back buffer
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
  parameter TBUFD = 0,  // accept to atan_rom's input (TABLE_BUF_DELAY); 0: the table is a ROM
  parameter FW   = 6,   // width of the in-flight count: 2^FW > L + 2
  parameter LAT  = 24,  // documented latency, accept to valid_o (the manifest's "latency")
  parameter INV  = 1,   // 1: assert the inductive invariants inv_* too (the proof); 0: only the
                        // properties (a bounded search for a planted fault reports those)
  parameter CHK  = 0    // 0: assert every assertion; g >= 1: assert only group g and assume
                        // that every assertion held at every earlier clock (see past_ok_q)
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
  localparam TBW = TBUFD > 0 ? TBUFD : 1;
  localparam TBI = TBUFD > 0 ? TBUFD - 1 : 0;
  wire [TBW-1:0]  p_tb;     // u_table_buf_delay's line (TBUFD > 0)
  wire            p_trd;    // atan_rom's rd_buf_i (TBUFD > 0)
  wire            p_twrbuf; // atan_rom's wr_buf_i (TBUFD > 0)
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

  // Bounded response: hi_q counts the edges in a row with ready_i high (saturating at LAT + 1);
  // win_q[k] is the number of samples accepted at the last k + 1 edges (at each edge it takes
  // win_q[k - 1] plus this edge's acceptance), so win_q[LAT - 1] counts the last LAT.
  // Kept as a shift of partial sums rather than a sum over a history of acceptances so that
  // the induction step compares each partial sum with one stage (inv_live_s), never a whole
  // reordered sum.
  reg [FW-1:0] hi_q;
  reg [FW-1:0] win_q [0:LAT-1];
  integer      j;
  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      hi_q <= {FW{1'b0}};
      for (j = 0; j < LAT; j = j + 1) win_q[j] <= {FW{1'b0}};
    end else begin
      hi_q     <= !ready_i ? {FW{1'b0}} : (hi_q > LAT ? hi_q : hi_q + 1'b1);
      win_q[0] <= {{FW-1{1'b0}}, acc};
      for (j = 1; j < LAT; j = j + 1) win_q[j] <= win_q[j-1] + {{FW-1{1'b0}}, acc};
    end
  end
  wire [FW-1:0] recent = win_q[LAT-1];  // samples accepted at the last LAT edges

  // The inductive invariants, stated stage by stage: each relates stage k only to stage k - 1
  // (or to the model's counters), so that the induction step is many small local facts rather
  // than one count over the whole pipeline (that global form, a running count of the valid
  // stages from the queue back, did not finish in 15 minutes of z3 or 11 of yices at 23
  // stages; this one, in the groups below, takes about a minute). u_side_delay's line is
  // loaded from side_i = in_q at every enabled edge, bubble or not, so stage k's tag is in_q
  // as it was when stage k was loaded: for a valid stage its sample's tag, for a bubble the
  // tag of the next sample accepted after it. Hence, writing d[k] = in_q - tag[k] (the samples accepted since stage k was loaded):
  //   d[0] = v[0], d[k] = d[k - 1] + v[k]   (tag[k - 1] = tag[k] + v[k]), and d[k] <= k + 1;
  //   at the pipeline's end, out_q + head + skid = tag[L - 1] (the next tag to enter the queue)
  //   and fly_q = head + skid + d[L - 1].
  // The side line has no reset: fill_q counts the enabled edges since reset (saturating at L),
  // and the stages from fill_q on, not loaded since reset, hold no valid sample; the end of the
  // chain is stage fill_q - 1 until the line is full.
  reg [FW-1:0] fill_q;
  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      fill_q <= {FW{1'b0}};
    end else if (p_en && fill_q < L) begin
      fill_q <= fill_q + 1'b1;
    end
  end
  reg [SD-1:0] d [0:L-1];
  reg          fill_ok;  // fill_q <= L, and no valid sample in a stage not loaded since reset
  reg          chain_ok; // tag[k - 1] = tag[k] + v[k] (d[0] = v[0])
  reg          bound_ok; // d[k] <= k + 1
  reg          end_ok;   // the chain's end against the queue and fly_q
  reg          rd_ok;    // each valid buffer bit before map_lookup is its sample's
  reg          q_ok;     // the output queue holds the oldest samples, in order
  reg [SD-1:0] qn;       // head + skid
  reg          live_ok;  // while ready_i has been high: the pipeline holds the last acceptances
  integer      k;
  always @* begin
    fill_ok  = fill_q <= L;
    chain_ok = 1'b1;
    bound_ok = 1'b1;
    end_ok   = 1'b1;
    // While ready_i has been high for hi_q edges, the enable was high at all but the first.
    live_ok = hi_q < 2 || fill_q >= hi_q - 1 || fill_q == L;
    rd_ok  = 1'b1;
    qn     = {{SD-1{1'b0}}, p_head} + {{SD-1{1'b0}}, p_skid};
    q_ok   = (!p_head || side_o == out_q) && (!p_skid || (p_head && p_skid_s == out_q + 1'b1));
    if (fill_q == {FW{1'b0}}) begin
      end_ok = in_q == out_q && !p_head && !p_skid && fly_q == {FW{1'b0}};
    end
    for (k = 0; k < L; k = k + 1) begin
      d[k] = in_q - p_s[k*SD +: SD];
      if (fill_q <= k) begin
        fill_ok = fill_ok && !p_v[k];
      end else begin
        if (k == 0) chain_ok = chain_ok && d[k] == {{SD-1{1'b0}}, p_v[k]};
        else        chain_ok = chain_ok && p_s[(k-1)*SD +: SD] == p_s[k*SD +: SD] + p_v[k];
        bound_ok = bound_ok && d[k] <= k + 1;
        if (fill_q == k + 1) begin
          end_ok = end_ok && out_q + qn == p_s[k*SD +: SD]
                          && fly_q == {{FW-SD{1'b0}}, qn} + {{FW-SD{1'b0}}, d[k]};
        end
        // ... and stage k holds what was accepted at the last k + 1 edges: d[k] = win_q[k].
        if (hi_q >= k + 2) live_ok = live_ok && {{FW-SD{1'b0}}, d[k]} == win_q[k];
        if (k < BUFD && p_v[k]) rd_ok = rd_ok && p_b[k] == rec_q[p_s[k*SD +: SD]];
        if (k < TBUFD && p_v[k]) rd_ok = rd_ok && p_tb[k] == rec_q[p_s[k*SD +: SD]];
      end
    end
    // The head holds what was accepted LAT edges ago: with the line, the samples in flight
    // are those of the last LAT edges (a_live).
    if (hi_q > LAT && LAT == L + 1) begin
      live_ok = live_ok && win_q[LAT-1] == win_q[LAT-2] + {{FW-1{1'b0}}, p_head};
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

  // Each assertion's condition (1: it holds), its guard included. rs: in reset, or after the
  // last edge in reset (nothing in flight, ready_o low); first: the first edge with rst_ni high.
  wire rs    = !rst_ni || !prev_rst_q;
  wire first = !prev2_rst_q;
  wire c_rdy_reset = !rs || (!ready_o && !valid_o && !p_skid && p_v == {L{1'b0}} && fly_q == {FW{1'b0}});
  wire c_front0    = !rs || (p_front == front_q && !p_head && in_q == out_q && fill_q == {FW{1'b0}});
  wire c_live0     = !rs || hi_q == {FW{1'b0}};
  wire c_queue     = rs || q_ok;
  wire c_fill      = rs || fill_ok;
  wire c_chain     = rs || chain_ok;
  wire c_bound     = rs || bound_ok;
  wire c_end       = rs || end_ok;
  wire c_rd        = rs || rd_ok;
  wire c_front     = rs || p_front == front_q;
  wire c_en        = rs || p_en == !p_skid;
  wire c_fly       = rs || !valid_o || fly_q != {FW{1'b0}};
  wire c_order     = rs || !pop || side_o == out_q;
  wire c_rd_buf    = rs || !p_v[BUFD-1] || p_rd == rec_q[p_s[(BUFD-1)*SD +: SD]];
  wire c_rdy_en    = rs || ready_o == p_en;
  wire c_head      = rs || valid_o == p_head;
  wire c_live_q    = rs || hi_q == {FW{1'b0}} || (!p_skid && p_en);
  wire c_live_s    = rs || live_ok;
  wire c_live      = rs || hi_q <= LAT || fly_q == recent;
  wire c_rdy_first = rs || !first || ready_o;
  wire c_hold      = rs || first || !stall_q || (valid_o && i_o == i_q && zero_o == zero_q && side_o == side_q);
  wire c_rdy_rule  = rs || first || ready_o || stall_q;
  wire c_wr_buf    = p_wrbuf == !front_d;
  wire c_tbl_rd_buf = TBUFD == 0 || rs || !p_v[TBI] || p_trd == rec_q[p_s[TBI*SD +: SD]];
  wire c_tbl_wr_buf = TBUFD == 0 || p_twrbuf == !front_d;
  wire props_ok = c_rdy_reset && c_fly && c_order && c_rd_buf && c_rdy_en && c_head && c_live
               && c_rdy_first && c_hold && c_rdy_rule && c_wr_buf && c_tbl_rd_buf
               && c_tbl_wr_buf;
  wire invs_ok  = c_front0 && c_live0 && c_queue && c_fill && c_chain && c_bound && c_end && c_rd
               && c_front && c_en && c_live_q && c_live_s;

  // The proof in groups (CHK = g): the induction step of the whole set of assertions is one
  // query per group, "all hold at clock t, so group g holds at t + 1", which the solver answers
  // far faster than the conjunction at once (the whole set at 23 stages: no answer in 10
  // minutes of yices). past_ok_q carries "every assertion held at the last clock" (1 in the
  // first clock) and is assumed. That is sound: if every group holds at every clock before t
  // on a trace, the trace meets the assumption up to t, and so each group, proven under it,
  // holds at t; by induction over t every assertion holds at every clock.
  reg past_ok_q = 1'b1;
  always @(posedge clk_i) begin
    past_ok_q <= props_ok && invs_ok;
  end
  always @* begin
    if (CHK != 0) assume (past_ok_q);
  end

  // The groups: 1 ready_o, reset and the front register; 2 the output queue; 3 to 6 the
  // pipeline's chain; 7 the map buffer; 8 the bounded response.
  always @* begin
    if (CHK == 0 || CHK == 1) begin
      a_rdy_reset: assert (c_rdy_reset);
      a_rdy_en:    assert (c_rdy_en);
      a_head:      assert (c_head);
      a_rdy_first: assert (c_rdy_first);
      a_rdy_rule:  assert (c_rdy_rule);
      a_wr_buf:    assert (c_wr_buf);
      a_tbl_wr_buf: assert (c_tbl_wr_buf);
      if (INV) begin inv_front0: assert (c_front0); end
      if (INV) begin inv_live0:  assert (c_live0); end
      if (INV) begin inv_front:  assert (c_front); end
      if (INV) begin inv_en:     assert (c_en); end
      if (INV) begin inv_live_q: assert (c_live_q); end
    end
    if (CHK == 0 || CHK == 2) begin
      a_fly:       assert (c_fly);
      a_order:     assert (c_order);
      a_hold:      assert (c_hold);
      if (INV) begin inv_queue:  assert (c_queue); end
    end
    if (INV && (CHK == 0 || CHK == 3)) begin inv_fill:  assert (c_fill); end
    if (INV && (CHK == 0 || CHK == 4)) begin inv_chain: assert (c_chain); end
    if (INV && (CHK == 0 || CHK == 5)) begin inv_bound: assert (c_bound); end
    if (INV && (CHK == 0 || CHK == 6)) begin inv_end:   assert (c_end); end
    if (CHK == 0 || CHK == 7) begin
      a_rd_buf:    assert (c_rd_buf);
      a_tbl_rd_buf: assert (c_tbl_rd_buf);
      if (INV) begin inv_rd:     assert (c_rd); end
    end
    if (CHK == 0 || CHK == 8) begin
      a_live:      assert (c_live);
      if (INV) begin inv_live_s: assert (c_live_s); end
    end
  end

endmodule

`default_nettype wire
