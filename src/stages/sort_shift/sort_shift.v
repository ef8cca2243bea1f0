{= h.header =}
`default_nettype none

// Sort & shift: split off the signs, find the largest magnitude (ties go to the lowest axis),
// and shift all three magnitudes left by the max's leading zeros before keeping their top R
// bits, so that small gradients keep their precision. (u, v) are the other two components
// in axis order: max x gives (y, z), max y gives (x, z), max z gives (x, y).
// {% if mag_reg %}Stage 0 takes magnitudes; stage 1 compares{% else %}Stage 1 takes magnitudes, compares{% endif %} them and counts leading zeros (all three in
// parallel, so the count does not wait for the compare){% if cmp_reg %}, registers that, and selects{% else %} and selects{% endif %};
// stage 2 shifts. Latency {= latency =}.
module {= h.module =} (
{= h.ports =}
);

  localparam G   = {= g =};  // gradient width; a magnitude needs all G bits for -2^(G-1)
  localparam R   = {= r =};  // reduced magnitude width
  localparam SHW = {= shw =};  // width of a left shift, 0..G-1
  localparam LATENCY = {= latency =};

  // ---------------------------------------------------------------- {% if mag_reg %}stage 0{% else %}stage 1{% endif %}
  wire [G-1:0] mag_x_d, mag_y_d, mag_z_d;
  assign mag_x_d = gx_i[G-1] ? ({G{1'b0}} - gx_i) : gx_i;
  assign mag_y_d = gy_i[G-1] ? ({G{1'b0}} - gy_i) : gy_i;
  assign mag_z_d = gz_i[G-1] ? ({G{1'b0}} - gz_i) : gz_i;
{%- if mag_reg %}

  // The negation's carry chain and the compare's are a clock apart (pipeline_depth >= 1).
  reg [G-1:0] mag_x, mag_y, mag_z;
  reg         neg_x, neg_y, neg_z;

  always @(posedge clk_i) begin
    if (en_i) begin
      mag_x <= mag_x_d;
      mag_y <= mag_y_d;
      mag_z <= mag_z_d;
      neg_x <= gx_i[G-1];
      neg_y <= gy_i[G-1];
      neg_z <= gz_i[G-1];
    end
  end

  // ---------------------------------------------------------------- stage 1
{%- else %}
  wire [G-1:0] mag_x, mag_y, mag_z;
  wire         neg_x, neg_y, neg_z;
  assign mag_x = mag_x_d;
  assign mag_y = mag_y_d;
  assign mag_z = mag_z_d;
  assign neg_x = gx_i[G-1];
  assign neg_y = gy_i[G-1];
  assign neg_z = gz_i[G-1];
{%- endif %}

  // Leading zeros of each magnitude inside G bits; a zero magnitude is not shifted.
  reg [SHW-1:0] lz_x_d, lz_y_d, lz_z_d;
{%- for c in comps %}
  always @* begin
{%- for (bit, lz) in lz_table %}
    {% if loop.first %}if     {% else %}else if{% endif %} (mag_{= c =}[{= bit =}]) lz_{= c =}_d = {= shw =}'d{= lz =};
{%- endfor %}
    else lz_{= c =}_d = {= shw =}'d0;  // zero: no shift
  end
{%- endfor %}

  wire x_ge_y_d, x_ge_z_d, y_ge_z_d;
  assign x_ge_y_d = mag_x >= mag_y;
  assign x_ge_z_d = mag_x >= mag_z;
  assign y_ge_z_d = mag_y >= mag_z;
{%- if cmp_reg %}

  // The compares' carry chains and the select are a clock apart (pipeline_depth 2).
  reg [G-1:0]   mag_x_s, mag_y_s, mag_z_s;
  reg           neg_x_s, neg_y_s, neg_z_s;
  reg [SHW-1:0] lz_x, lz_y, lz_z;
  reg           x_ge_y, x_ge_z, y_ge_z;

  always @(posedge clk_i) begin
    if (en_i) begin
      mag_x_s <= mag_x;
      mag_y_s <= mag_y;
      mag_z_s <= mag_z;
      neg_x_s <= neg_x;
      neg_y_s <= neg_y;
      neg_z_s <= neg_z;
      lz_x    <= lz_x_d;
      lz_y    <= lz_y_d;
      lz_z    <= lz_z_d;
      x_ge_y  <= x_ge_y_d;
      x_ge_z  <= x_ge_z_d;
      y_ge_z  <= y_ge_z_d;
    end
  end
{%- else %}
  wire [G-1:0]   mag_x_s, mag_y_s, mag_z_s;
  wire           neg_x_s, neg_y_s, neg_z_s;
  wire [SHW-1:0] lz_x, lz_y, lz_z;
  wire           x_ge_y, x_ge_z, y_ge_z;
  assign mag_x_s = mag_x;
  assign mag_y_s = mag_y;
  assign mag_z_s = mag_z;
  assign neg_x_s = neg_x;
  assign neg_y_s = neg_y;
  assign neg_z_s = neg_z;
  assign lz_x    = lz_x_d;
  assign lz_y    = lz_y_d;
  assign lz_z    = lz_z_d;
  assign x_ge_y  = x_ge_y_d;
  assign x_ge_z  = x_ge_z_d;
  assign y_ge_z  = y_ge_z_d;
{%- endif %}

  reg  [1:0]     axis_d;
  reg            s_max_d, s_u_d, s_v_d;
  reg  [G-1:0]   max_d, mu_d, mv_d;
  reg  [SHW-1:0] lz_d;
  always @* begin
    if (x_ge_y && x_ge_z) begin
      axis_d  = 2'd0;
      s_max_d = neg_x_s;  max_d = mag_x_s;  lz_d = lz_x;
      s_u_d   = neg_y_s;  mu_d  = mag_y_s;
      s_v_d   = neg_z_s;  mv_d  = mag_z_s;
    end else if (y_ge_z) begin
      axis_d  = 2'd1;
      s_max_d = neg_y_s;  max_d = mag_y_s;  lz_d = lz_y;
      s_u_d   = neg_x_s;  mu_d  = mag_x_s;
      s_v_d   = neg_z_s;  mv_d  = mag_z_s;
    end else begin
      axis_d  = 2'd2;
      s_max_d = neg_z_s;  max_d = mag_z_s;  lz_d = lz_z;
      s_u_d   = neg_x_s;  mu_d  = mag_x_s;
      s_v_d   = neg_y_s;  mv_d  = mag_y_s;
    end
  end

  reg  [1:0]     axis_q1;
  reg            s_max_q1, s_u_q1, s_v_q1;
  reg  [G-1:0]   max_q1, mu_q1, mv_q1;
  reg  [SHW-1:0] lz_q1;

  always @(posedge clk_i) begin
    if (en_i) begin
      axis_q1  <= axis_d;
      s_max_q1 <= s_max_d;
      s_u_q1   <= s_u_d;
      s_v_q1   <= s_v_d;
      max_q1   <= max_d;
      mu_q1    <= mu_d;
      mv_q1    <= mv_d;
      lz_q1    <= lz_d;
    end
  end

  // ---------------------------------------------------------------- stage 2
  // Shifting by the max's leading zeros never overflows G bits (u and v are <= max).
  wire [G-1:0] max_sh, mu_sh, mv_sh;
  assign max_sh = max_q1 << lz_q1;
  assign mu_sh  = mu_q1 << lz_q1;
  assign mv_sh  = mv_q1 << lz_q1;
{%- if truncates %}

  // The bits below the top R are dropped.
  wire unused_sh_low;
  assign unused_sh_low = ^{max_sh[G-R-1:0], mu_sh[G-R-1:0], mv_sh[G-R-1:0]};
{%- endif %}

  reg  [1:0]   axis_q2;
  reg          s_max_q2, s_u_q2, s_v_q2;
  reg  [R-1:0] m_q2, a_q2, b_q2;

  always @(posedge clk_i) begin
    if (en_i) begin
      axis_q2  <= axis_q1;
      s_max_q2 <= s_max_q1;
      s_u_q2   <= s_u_q1;
      s_v_q2   <= s_v_q1;
      m_q2     <= max_sh[G-1 -: R];
      a_q2     <= mu_sh[G-1 -: R];
      b_q2     <= mv_sh[G-1 -: R];
    end
  end

{%- include "valid_line.v" %}
  assign axis_o  = axis_q2;
  assign s_max_o = s_max_q2;
  assign s_u_o   = s_u_q2;
  assign s_v_o   = s_v_q2;
  assign m_o     = m_q2;
  assign a_o     = a_q2;
  assign b_o     = b_q2;

endmodule

`default_nettype wire
