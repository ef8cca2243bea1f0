{= h.header =}
`default_nettype none

// Linear index, in place of the atan ROM when distortion compensation is off: the position
// is the fraction scaled to 0..POS_MAX, p = (u * POS_MAX + 2^(F-1)) >> F (half up), and the
// all-ones code (tan = 1) goes to the border exactly: it is read as u' = 2^F, which gives
{%- if infer %}
// p = POS_MAX. u' * POS_MAX is a plain product by the constant, then + 2^(F-1), registered as
// pipeline_depth = {= depth =} places them (rmapgen::stages::linear_index::Plan). Latency {= latency =}.
{%- else %}
// p = POS_MAX. The constant POS_MAX = (2^I - 1) * 2^P makes u' * POS_MAX a sum of I shifted
// copies of u', an adder tree registered as pipeline_depth = {= depth =} places it
// (rmapgen::stages::linear_index::Plan). Latency {= latency =}.
{%- endif %}
module {= h.module =} (
{= h.ports =}
);

  localparam F   = {= f =};  // fraction width
  localparam POS = {= pos =};  // position width
  localparam LW  = {= lw =};  // u' * POS_MAX + HALF, 0..2^F * POS_MAX + HALF
  localparam LATENCY = {= latency =};

  // ---------------------------------------------------------------- u' and v'
  wire [F:0] ux_d, vx_d;
  assign ux_d = (u_i == {F{1'b1}}) ? {1'b1, {F{1'b0}}} : {1'b0, u_i};
  assign vx_d = (v_i == {F{1'b1}}) ? {1'b1, {F{1'b0}}} : {1'b0, v_i};
{%- if pre_reg %}

  reg [F:0] ux_{= in_q =}, vx_{= in_q =};

  always @(posedge clk_i) begin
    if (en_i) begin
      ux_{= in_q =} <= ux_d;
      vx_{= in_q =} <= vx_d;
    end
  end
{%- endif %}
{%- include "steps.v" %}

  // ---------------------------------------------------------------- positions
  wire [LW-1:0] su, sv;
  assign su = {= sum_u =};
  assign sv = {= sum_v =};

  wire unused_round;
  assign unused_round = ^{su[F-1:0], sv[F-1:0]};
{%- include "valid_line.v" %}
  assign pu_o    = su[F+POS-1:F];
  assign pv_o    = sv[F+POS-1:F];

endmodule

`default_nettype wire
