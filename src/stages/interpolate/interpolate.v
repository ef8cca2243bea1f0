{= h.header =}
`default_nettype none

// Bilinear interpolation of four neighbours with weights 0..S (S = 2^P), rounded once:
//   a0 = e00 (S - wu) + e10 wu + S/2,  a1 = e01 (S - wu) + e11 wu + S/2   (u pass)
//   r  = a0 (S - wv) + a1 wv,          i  = r >> 2P                        (v pass)
// The S/2 of the u pass becomes the rounding constant S*S/2 of the v pass, so
{%- if infer %}
// i = (e00*S*S + (e10-e00)*wu*S + ...) rounded half up, as in the model. Each pass is two plain
// products (DSP blocks with their output registers), all unsigned, then their sum, registered
// as pipeline_depth = {= depth =} places them (rmapgen::stages::interpolate::Plan). Latency {= latency =}.
{%- else %}
// i = (e00*S*S + (e10-e00)*wu*S + ...) rounded half up, as in the model. Each pass is an adder
// tree of weight-gated partial products (w[j] ? e << j : 0), all unsigned, one LUT level and
// one carry chain per level, registered as pipeline_depth = {= depth =} places them
// (rmapgen::stages::interpolate::Plan). Latency {= latency =}.
{%- endif %}
module {= h.module =} (
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

  reg [M-1:0] e00_{= in_q =}, e10_{= in_q =}, e01_{= in_q =}, e11_{= in_q =};
  reg [P:0]   wu_{= in_q =}, wv_{= in_q =}, wuc_{= in_q =}, wvc_{= in_q =};

  always @(posedge clk_i) begin
    if (en_i) begin
      e00_{= in_q =} <= e00_i;
      e10_{= in_q =} <= e10_i;
      e01_{= in_q =} <= e01_i;
      e11_{= in_q =} <= e11_i;
      wu_{= in_q =}  <= wu_i;
      wv_{= in_q =}  <= wv_i;
      wuc_{= in_q =} <= wuc_d;
      wvc_{= in_q =} <= wvc_d;
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
