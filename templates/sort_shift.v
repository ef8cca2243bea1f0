{= h.header =}
`default_nettype none

// Sort & shift: split off the signs, find the largest magnitude (ties go to the lowest axis),
// and shift all three magnitudes left by the max's leading zeros before keeping their top R
// bits, so that small gradients keep their precision. (u, v) are the other two components
// in axis order: max x gives (y, z), max y gives (x, z), max z gives (x, y).
// Stage 1 takes magnitudes, compares them and counts leading zeros (all three in parallel,
// so the count does not wait for the compare); stage 2 shifts. Latency 2.
module sort_shift (
{= h.ports =}
);

  localparam G   = {= g =};  // gradient width; a magnitude needs all G bits for -2^(G-1)
  localparam R   = {= r =};  // reduced magnitude width
  localparam SHW = {= shw =};  // width of a left shift, 0..G-1

  // ---------------------------------------------------------------- stage 1
  wire [G-1:0] mag_x, mag_y, mag_z;
  assign mag_x = gx_i[G-1] ? ({G{1'b0}} - gx_i) : gx_i;
  assign mag_y = gy_i[G-1] ? ({G{1'b0}} - gy_i) : gy_i;
  assign mag_z = gz_i[G-1] ? ({G{1'b0}} - gz_i) : gz_i;

  // Leading zeros of each magnitude inside G bits; a zero magnitude is not shifted.
  reg [SHW-1:0] lz_x, lz_y, lz_z;
{%- for c in comps %}
  always @* begin
{%- for (bit, lz) in lz_table %}
    {% if loop.first %}if     {% else %}else if{% endif %} (mag_{= c =}[{= bit =}]) lz_{= c =} = {= shw =}'d{= lz =};
{%- endfor %}
    else lz_{= c =} = {= shw =}'d0;  // zero: no shift
  end
{%- endfor %}

  wire x_ge_y, x_ge_z, y_ge_z;
  assign x_ge_y = mag_x >= mag_y;
  assign x_ge_z = mag_x >= mag_z;
  assign y_ge_z = mag_y >= mag_z;

  reg  [1:0]     axis_d;
  reg            s_max_d, s_u_d, s_v_d;
  reg  [G-1:0]   max_d, mu_d, mv_d;
  reg  [SHW-1:0] lz_d;
  always @* begin
    if (x_ge_y && x_ge_z) begin
      axis_d  = 2'd0;
      s_max_d = gx_i[G-1];  max_d = mag_x;  lz_d = lz_x;
      s_u_d   = gy_i[G-1];  mu_d  = mag_y;
      s_v_d   = gz_i[G-1];  mv_d  = mag_z;
    end else if (y_ge_z) begin
      axis_d  = 2'd1;
      s_max_d = gy_i[G-1];  max_d = mag_y;  lz_d = lz_y;
      s_u_d   = gx_i[G-1];  mu_d  = mag_x;
      s_v_d   = gz_i[G-1];  mv_d  = mag_z;
    end else begin
      axis_d  = 2'd2;
      s_max_d = gz_i[G-1];  max_d = mag_z;  lz_d = lz_z;
      s_u_d   = gx_i[G-1];  mu_d  = mag_x;
      s_v_d   = gy_i[G-1];  mv_d  = mag_y;
    end
  end

  reg            valid_q1;
  reg  [1:0]     axis_q1;
  reg            s_max_q1, s_u_q1, s_v_q1;
  reg  [G-1:0]   max_q1, mu_q1, mv_q1;
  reg  [SHW-1:0] lz_q1;

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      valid_q1 <= 1'b0;
    end else if (en_i) begin
      valid_q1 <= valid_i;
    end
  end

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

  reg          valid_q2;
  reg  [1:0]   axis_q2;
  reg          s_max_q2, s_u_q2, s_v_q2;
  reg  [R-1:0] m_q2, a_q2, b_q2;

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      valid_q2 <= 1'b0;
    end else if (en_i) begin
      valid_q2 <= valid_q1;
    end
  end

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

  assign valid_o = valid_q2;
  assign axis_o  = axis_q2;
  assign s_max_o = s_max_q2;
  assign s_u_o   = s_u_q2;
  assign s_v_o   = s_v_q2;
  assign m_o     = m_q2;
  assign a_o     = a_q2;
  assign b_o     = b_q2;

endmodule

`default_nettype wire
