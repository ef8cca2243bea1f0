{= h.header =}
`default_nettype none

// Colour multiply: each 8-bit channel of the sample colour times the intensity, scaled so
// that full intensity keeps the colour: round(c * i / D), half up, D = 2^M - 1. The division
// by the constant 2D is a multiply by K and a shift by S (exact for every input; see
// rmapgen's model, color_mul::constants): out = ((2*c*i + D) * K) >> S.
{%- if infer %}
// The numerator is the plain product c * i, doubled, plus D; then the plain product by K (DSP
// blocks with their output registers), registered as pipeline_depth = {= depth =} places them
// (rmapgen::stages::color_mul::Plan). Latency {= latency =}.
{%- else %}
// The numerator is an adder tree of colour-bit-gated copies of the intensity
// (c[j] ? i << (j+1) : 0) plus D; the product by K a tree of shifted copies of the numerator,
// one per set bit of K. One LUT level and one carry chain per level, registered as
// pipeline_depth = {= depth =} places them (rmapgen::stages::color_mul::Plan). Latency {= latency =}.
{%- endif %}
module {= h.module =} (
{= h.ports =}
);

  localparam S  = {= s =};  // shift of the constant division
  localparam PW = {= pw =};  // numerator * K; the quotient (<= 255) sits above S
  localparam LATENCY = {= latency =};
  // K = {= k =} = ceil(2^S / 2D), D = {= d =}{% if !infer %}: the set bits of K are the product tree's terms{% endif %}.
{%- include "steps.v" %}

  // ---------------------------------------------------------------- quotients
  wire [PW-1:0] pr, pg, pb;
  assign pr = {= pr =};
  assign pg = {= pg =};
  assign pb = {= pb =};

  wire unused_low;
  assign unused_low = ^{pr[S-1:0], pg[S-1:0], pb[S-1:0]};
{%- include "valid_line.v" %}
  assign r_o     = pr[PW-1:S];
  assign g_o     = pg[PW-1:S];
  assign b_o     = pb[PW-1:S];

endmodule

`default_nettype wire
