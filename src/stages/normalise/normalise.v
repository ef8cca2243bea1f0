{= h.header =}
`default_nettype none

// Normalise: u = a / m and v = b / m as F-bit fractions, computed as a * (1/m) with the
// reciprocal ROM, rounded half up:
//   u = min(2^F-1, (a*recip + 2^(SH-1)) >> SH).
// A component equal to the max saturates to all ones, which the index stages read as exactly
// 1. The first clock reads the ROM and compares;{% if rom_reg %} the next registers the ROM's output;{% endif %} then
{%- if infer %}
// a * recip is a plain product (a DSP block with its output register), then + HALF, registered
// as pipeline_depth = {= depth =} places them
{%- else %}
// a * recip + HALF is an adder tree of the partial products (a[j] ? recip << j : 0), one LUT
// level and one carry chain per level, registered as pipeline_depth = {= depth =} places them
{%- endif %}
// (rmapgen::stages::normalise::Plan); the last clock rounds and saturates. Latency {= latency =}.
module {= h.module =}{= h.params =} (
{= h.ports =}
);

  localparam R  = {= r =};  // reduced magnitude width
  localparam W  = {= w =};  // reciprocal width
  localparam F  = {= f =};  // fraction width
  localparam RA = {= ra =};  // reciprocal ROM address width
  localparam SH = {= sh =};  // a * recip >> SH is an F-bit fraction: R-1+W-F
  localparam SW = {= sw =};  // a * recip + HALF ({% if infer %}the product and sum{% else %}the adder tree{% endif %}'s result)
  localparam LATENCY = {= latency =};

  // ---------------------------------------------------------------- ROM read and compare
  wire [W-1:0] recip_q1;  // registered inside the ROM
{%- if outside %}
  // The ROM is shared with another lane in rmap_lanes: this lane reads one of its ports, on
  // this stage's enable, and gets the data one clock later as from its own ROM.
  assign recip_en_o   = en_i;
  assign recip_addr_o = m_i[RA-1:0];
  assign recip_q1     = recip_data_i;
{%- else %}
  {= rom =}{= rom_params =} u_recip_rom (
    .clk_i  (clk_i),
    .en_i   (en_i),
    .addr_i (m_i[RA-1:0]),
    .data_o (recip_q1)
  );
{%- endif %}

  reg [R-1:0] a_q1, b_q1;
  reg         a_max_q1, b_max_q1;

  always @(posedge clk_i) begin
    if (en_i) begin
      a_q1     <= a_i;
      b_q1     <= b_i;
      a_max_q1 <= (a_i == m_i);
      b_max_q1 <= (b_i == m_i);
    end
  end
{%- if rom_reg %}

  // ---------------------------------------------------------------- ROM output register
  // The block RAM's clock-to-output is slow; the multipliers start from a fabric register.
  reg [W-1:0] recip_{= tree_q =};
  reg [R-1:0] a_{= tree_q =}, b_{= tree_q =};
  reg         a_max_{= tree_q =}, b_max_{= tree_q =};

  always @(posedge clk_i) begin
    if (en_i) begin
      recip_{= tree_q =} <= recip_q1;
      a_{= tree_q =}     <= a_q1;
      b_{= tree_q =}     <= b_q1;
      a_max_{= tree_q =} <= a_max_q1;
      b_max_{= tree_q =} <= b_max_q1;
    end
  end
{%- endif %}
{%- include "steps.v" %}

  // ---------------------------------------------------------------- round and saturate
  wire [SW-1:0] sa, sb;
  assign sa = {= sum_a =};
  assign sb = {= sum_b =};

  // Anything at or above 2^F after the shift saturates.
  wire sat_a, sat_b;
  assign sat_a = {= a_max =} || (|sa[SW-1:SH+F]);
  assign sat_b = {= b_max =} || (|sb[SW-1:SH+F]);

  wire unused_round;
  assign unused_round = ^{sa[SH-1:0], sb[SH-1:0]};

  reg [F-1:0] u_q, v_q;

  always @(posedge clk_i) begin
    if (en_i) begin
      u_q <= sat_a ? {F{1'b1}} : sa[SH+F-1:SH];
      v_q <= sat_b ? {F{1'b1}} : sb[SH+F-1:SH];
    end
  end
{%- include "valid_line.v" %}
  assign u_o     = u_q;
  assign v_o     = v_q;

endmodule

`default_nettype wire
