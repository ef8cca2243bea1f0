{= h.header =}
`default_nettype none

// Bilinear interpolation of four neighbours with weights 0..S (S = 2^P): first along u,
// a0 = e00*S + (e10 - e00)*wu and a1 = e01*S + (e11 - e01)*wu (exact), then along v,
// r = a0*S + (a1 - a0)*wv, rounded once: i = (r + S*S/2) >> 2P. Each pass lies between its
// inputs, so it is computed modulo 2^width in unsigned arithmetic, which is exact, and as
// one sum of products (e10*wu - e00*wu), which synthesis turns into a single adder tree.
// Stage 1 is the u pass, stage 2 the v pass and the rounding. Latency 2.
module interpolate (
{= h.ports =}
);

  localparam M  = {= m =};  // entry width
  localparam P  = {= p =};  // weight fraction bits
  localparam AW = {= aw =};  // u pass, 0..(2^M-1)*S
  localparam RW = {= rw =};  // v pass plus HALF, 0..(2^M-1)*S*S + S*S/2
  localparam [RW-1:0] HALF = {= rw =}'d{= half =};  // S*S/2

  // ---------------------------------------------------------------- stage 1
  // e10*wu - e00*wu rather than (e10 - e00)*wu: no subtraction in front of the multipliers,
  // so the whole pass is one sum of partial products.
  wire [AW-1:0] e00_s, e01_s, e00_x, e10_x, e01_x, e11_x, wu_x;
  assign e00_s = {e00_i, {P{1'b0}}};
  assign e01_s = {e01_i, {P{1'b0}}};
  assign e00_x = {{P{1'b0}}, e00_i};
  assign e10_x = {{P{1'b0}}, e10_i};
  assign e01_x = {{P{1'b0}}, e01_i};
  assign e11_x = {{P{1'b0}}, e11_i};
  assign wu_x  = {{(AW-P-1){1'b0}}, wu_i};

  reg          valid_q1;
  reg [AW-1:0] a0_q1, a1_q1;
  reg [P:0]    wv_q1;

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      valid_q1 <= 1'b0;
    end else if (en_i) begin
      valid_q1 <= valid_i;
    end
  end

  always @(posedge clk_i) begin
    if (en_i) begin
      a0_q1 <= e00_s + e10_x * wu_x - e00_x * wu_x;
      a1_q1 <= e01_s + e11_x * wu_x - e01_x * wu_x;
      wv_q1 <= wv_i;
    end
  end

  // ---------------------------------------------------------------- stage 2
  wire [RW-1:0] a0_s, a0_x, a1_x, wv_x, r;
  assign a0_s = {a0_q1, {P{1'b0}}};
  assign a0_x = {{P{1'b0}}, a0_q1};
  assign a1_x = {{P{1'b0}}, a1_q1};
  assign wv_x = {{(RW-P-1){1'b0}}, wv_q1};
  assign r    = a0_s + a1_x * wv_x - a0_x * wv_x + HALF;

  wire unused_round;
  assign unused_round = ^r[2*P-1:0];

  reg         valid_q2;
  reg [M-1:0] i_q2;

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      valid_q2 <= 1'b0;
    end else if (en_i) begin
      valid_q2 <= valid_q1;
    end
  end

  always @(posedge clk_i) begin
    if (en_i) begin
      i_q2 <= r[RW-1:2*P];
    end
  end

  assign valid_o = valid_q2;
  assign i_o     = i_q2;

endmodule

`default_nettype wire
