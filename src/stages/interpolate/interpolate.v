{= h.header =}
`default_nettype none

// Bilinear interpolation of four neighbours with weights 0..S (S = 2^P), rounded once:
//   a0 = e00 (S - wu) + e10 wu + S/2,  a1 = e01 (S - wu) + e11 wu + S/2   (u pass)
//   r  = a0 (S - wv) + a1 wv,          i  = r >> 2P                        (v pass)
// The S/2 of the u pass becomes the rounding constant S*S/2 of the v pass, so
// i = (e00*S*S + (e10-e00)*wu*S + ...) rounded half up, as in the model. Each pass is an adder
// tree of weight-gated partial products (w[j] ? e << j : 0), all unsigned, one LUT level and
// one carry chain per level, registered as pipeline_depth = {= depth =} places them
// (rmapgen::stages::interpolate::Plan). Latency {= latency =}.
module interpolate (
{= h.ports =}
);

  localparam M  = {= m =};  // entry width
  localparam P  = {= p =};  // weight fraction bits
  localparam RW = {= rw =};  // v pass r, 0..(2^M-1)*S*S + S*S/2
  localparam [P:0] S = {= p + 1 =}'d{= s =};  // 2^P, the largest weight
  localparam LATENCY = {= latency =};

  // ---------------------------------------------------------------- weight complements
  wire [P:0] wuc_d, wvc_d;
  assign wuc_d = S - wu_i;
  assign wvc_d = S - wv_i;
{%- if in_reg %}

  reg [M-1:0] e00_q1, e10_q1, e01_q1, e11_q1;
  reg [P:0]   wu_q1, wv_q1, wuc_q1, wvc_q1;

  always @(posedge clk_i) begin
    if (en_i) begin
      e00_q1 <= e00_i;
      e10_q1 <= e10_i;
      e01_q1 <= e01_i;
      e11_q1 <= e11_i;
      wu_q1  <= wu_i;
      wv_q1  <= wv_i;
      wuc_q1 <= wuc_d;
      wvc_q1 <= wvc_d;
    end
  end
{%- endif %}
{%- include "steps.v" %}

  // ---------------------------------------------------------------- result
  wire [RW-1:0] r;
  assign r = {= sum_r =};

  wire unused_round;
  assign unused_round = ^r[2*P-1:0];
{%- include "valid_line.v" %}
  assign i_o     = r[2*P+M-1:2*P];

endmodule

`default_nettype wire
