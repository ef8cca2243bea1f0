{= h.header =}
`default_nettype none

// Reflectance-map shader: gradient in, intensity out, one sample per clock.
// zero_detect runs beside sort_shift -> normalise -> {= position =} -> map_lookup{% if interpolation %} -> interpolate{% endif %}{% if color %} -> color_mul{% endif %};
// pipe_delay lines carry the sideband (signs, axis, buffer{% if color %}, colour{% endif %}, zero flag{% if sd > 0 %}, side_i{% endif %}) beside the
// stages, and one output register applies the zero flag.
// Stage latencies: {= latency_list =}, output register 1: total {= total =}.
{%- if handshake %}
// Flow control (valid/ready, AXI-Stream style): a sample is accepted at a rising edge with
// valid_i && ready_o, a result leaves with valid_o && ready_i. The results wait in a
// two-entry queue (the output register and a skid register); the whole pipeline advances
// (every stage's en_i) while the skid register is free, so ready_i low stalls it without
// losing or repeating a sample. The enable and ready_o are registers: ready_i reaches no
// clock enable and no output combinationally. valid_o and the outputs hold while ready_i
// is low. Latency {= total =} enabled clocks (clocks with ready_o high), plus any wait in the queue.
{%- endif %}
// Map buffers: a sample accepted in the cycle of swap_i or later reads the new front buffer;
// host writes go to the back buffer. After a swap, let the samples accepted before it leave
// ({% if handshake %}the last of them leaves with valid_o && ready_i{% else %}LATENCY clocks{% endif %}) before writing into the old front buffer.
module {= h.module =}{= h.params =} (
{= h.ports =}
);

  localparam R   = {= r =};  // reduced magnitude width
  localparam F   = {= f =};  // fraction width
  localparam POS = {= pos =};  // map position width
  localparam M   = {= m =};  // map entry and intensity width
{%- if interpolation %}
  localparam P   = {= p =};  // interpolation weight fraction bits
{%- endif %}
{%- if color %}
  localparam C   = {= c =};  // colour channel width
{%- endif %}
{%- if sd > 0 %}
  localparam SD  = {= sd =};  // side_i width: {% if axis %}{tuser, tlast} of the AXI4-Stream top{% else %}the lane's valid bit (rmap_lanes){% endif %}
{%- endif %}

  // Sideband delays, from rmapgen::stages::rmap_top (the stage latencies above).
  localparam SIGN_DELAY = {= sign_delay =};  // sort_shift out to map_lookup in
  localparam BUF_DELAY  = {= buf_delay =};  // accept to map_lookup in
  localparam ZERO_DELAY = {= zero_delay =};  // zero_detect out to the output register
{%- if color %}
  localparam RGB_DELAY  = {= rgb_delay =};  // accept to color_mul in
  localparam I_DELAY    = {= i_delay =};  // intensity beside color_mul
{%- endif %}
{%- if sd > 0 %}
  localparam SIDE_DELAY = {= side_delay =};  // accept to the output register
{%- endif %}
{%- if table_ram %}
  localparam TABLE_BUF_DELAY = {= table_buf_delay =};  // accept to {= position =} in
{%- endif %}

{%- if handshake %}
  // Every stage's clock enable: a register (see the flow control below).
  wire en;
{%- else %}
  // The plain valid stream never stalls: every stage's clock enable is tied high.
  wire en;
  assign en = 1'b1;
{%- endif %}

  // ---------------------------------------------------------------- map buffers
  reg  front_q;
  wire front_d;
  assign front_d = front_q ^ swap_i;

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      front_q <= 1'b0;
    end else begin
      front_q <= front_d;
    end
  end

  // ---------------------------------------------------------------- zero_detect
  wire unused_zd_valid;  // the valid bit travels through sort_shift
  wire zd_zero;

  {= mods.zero_detect =} u_zero_detect (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .en_i    (en),
    .valid_i (valid_i),
    .gx_i    (gx_i),
    .gy_i    (gy_i),
    .gz_i    (gz_i),
    .valid_o (unused_zd_valid),
    .zero_o  (zd_zero)
  );

  // ---------------------------------------------------------------- sort_shift
  wire         ss_valid;
  wire [1:0]   ss_axis;
  wire         ss_s_max, ss_s_u, ss_s_v;
  wire [R-1:0] ss_m, ss_a, ss_b;

  {= mods.sort_shift =} u_sort_shift (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .en_i    (en),
    .valid_i (valid_i),
    .gx_i    (gx_i),
    .gy_i    (gy_i),
    .gz_i    (gz_i),
    .valid_o (ss_valid),
    .axis_o  (ss_axis),
    .s_max_o (ss_s_max),
    .s_u_o   (ss_s_u),
    .s_v_o   (ss_s_v),
    .m_o     (ss_m),
    .a_o     (ss_a),
    .b_o     (ss_b)
  );

  // ---------------------------------------------------------------- normalise
  wire         nm_valid;
  wire [F-1:0] nm_u, nm_v;

  {= mods.normalise =}{= pars.normalise =} u_normalise (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .en_i    (en),
    .valid_i (ss_valid),
    .m_i     (ss_m),
    .a_i     (ss_a),
    .b_i     (ss_b),
    .valid_o (nm_valid),
    .u_o     (nm_u),
    .v_o     (nm_v){% if recip_out %},
    // The reciprocal ROM is shared with another lane, in rmap_lanes.
    .recip_en_o   (recip_en_o),
    .recip_addr_o (recip_addr_o),
    .recip_data_i (recip_data_i){% endif %}
  );

  // ---------------------------------------------------------------- {= position =}
  wire           ps_valid;
  wire [POS-1:0] ps_u, ps_v;
{%- if table_ram %}
  wire           ps_rd_buf;  // the buffer whose table the sample reads

  {= mods.pipe_delay =} #(
    .WIDTH (1),
    .DEPTH (TABLE_BUF_DELAY)
  ) u_table_buf_delay (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   (front_d),
    .q_o   (ps_rd_buf)
  );
{%- endif %}

  {= mods.position =}{= pars.position =} u_{= position =} (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .en_i    (en),
    .valid_i (nm_valid),
    .u_i     (nm_u),
    .v_i     (nm_v),
{%- if table_ram %}
    .rd_buf_i  (ps_rd_buf),
    .wr_en_i   (wr_en_i),
    .wr_buf_i  (~front_d),
    .wr_axis_i (wr_axis_i),
    .wr_addr_i (wr_addr_i),
    .wr_data_i (wr_data_i),
{%- endif %}
    .valid_o (ps_valid),
    .pu_o    (ps_u),
    .pv_o    (ps_v)
  );

  // ---------------------------------------------------------------- map_lookup
  wire [1:0] ml_axis;
  wire       ml_s_max, ml_s_u, ml_s_v;
  wire       ml_rd_buf;

  {= mods.pipe_delay =} #(
    .WIDTH (5),
    .DEPTH (SIGN_DELAY)
  ) u_sign_delay (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   ({ss_axis, ss_s_max, ss_s_u, ss_s_v}),
    .q_o   ({ml_axis, ml_s_max, ml_s_u, ml_s_v})
  );

  {= mods.pipe_delay =} #(
    .WIDTH (1),
    .DEPTH (BUF_DELAY)
  ) u_buf_delay (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   (front_d),
    .q_o   (ml_rd_buf)
  );

  wire         ml_valid;
  wire [M-1:0] ml_e00;
{%- if interpolation %}
  wire [M-1:0] ml_e10, ml_e01, ml_e11;
  wire [P:0]   ml_wu, ml_wv;
{%- endif %}

  {= mods.map_lookup =}{= pars.map_lookup =} u_map_lookup (
    .clk_i     (clk_i),
    .rst_ni    (rst_ni),
    .en_i      (en),
    .valid_i   (ps_valid),
    .axis_i    (ml_axis),
    .s_max_i   (ml_s_max),
    .s_u_i     (ml_s_u),
    .s_v_i     (ml_s_v),
    .pu_i      (ps_u),
    .pv_i      (ps_v),
    .rd_buf_i  (ml_rd_buf),
    .wr_en_i   (wr_en_i),
    .wr_buf_i  (~front_d),
    .wr_axis_i (wr_axis_i),
    .wr_addr_i (wr_addr_i),
    .wr_data_i (wr_data_i),
    .valid_o   (ml_valid),
{%- if interpolation %}
    .e00_o     (ml_e00),
    .e10_o     (ml_e10),
    .e01_o     (ml_e01),
    .e11_o     (ml_e11),
    .wu_o      (ml_wu),
    .wv_o      (ml_wv)
{%- else %}
    .e00_o     (ml_e00)
{%- endif %}
  );
{%- if interpolation %}

  // ---------------------------------------------------------------- interpolate
  wire         ip_valid;
  wire [M-1:0] ip_i;

  {= mods.interpolate =} u_interpolate (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .en_i    (en),
    .valid_i (ml_valid),
    .e00_i   (ml_e00),
    .e10_i   (ml_e10),
    .e01_i   (ml_e01),
    .e11_i   (ml_e11),
    .wu_i    (ml_wu),
    .wv_i    (ml_wv),
    .valid_o (ip_valid),
    .i_o     (ip_i)
  );
{%- endif %}

  // The intensity before the zero flag is applied.
  wire         lk_valid;
  wire [M-1:0] lk_i;
{%- if interpolation %}
  assign lk_valid = ip_valid;
  assign lk_i     = ip_i;
{%- else %}
  assign lk_valid = ml_valid;
  assign lk_i     = ml_e00;
{%- endif %}

  // ---------------------------------------------------------------- output
  wire         out_valid;  // at the output register's input
  wire [M-1:0] out_i;
  wire         out_zero;
{%- if color %}
  wire [C-1:0] out_r, out_g, out_b;
  wire [C-1:0] cm_r, cm_g, cm_b;  // the sample's colour, delayed to color_mul

  {= mods.pipe_delay =} #(
    .WIDTH (3 * C),
    .DEPTH (RGB_DELAY)
  ) u_rgb_delay (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   ({r_i, g_i, b_i}),
    .q_o   ({cm_r, cm_g, cm_b})
  );

  // Colour times the intensity before zeroing: for a zero gradient the output register
  // forces the colour to 0, which is also what the intensity 0 would give.
  {= mods.color_mul =} u_color_mul (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .en_i    (en),
    .valid_i (lk_valid),
    .i_i     (lk_i),
    .r_i     (cm_r),
    .g_i     (cm_g),
    .b_i     (cm_b),
    .valid_o (out_valid),
    .r_o     (out_r),
    .g_o     (out_g),
    .b_o     (out_b)
  );

  {= mods.pipe_delay =} #(
    .WIDTH (M),
    .DEPTH (I_DELAY)
  ) u_i_delay (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   (lk_i),
    .q_o   (out_i)
  );
{%- else %}
  assign out_valid = lk_valid;
  assign out_i     = lk_i;
{%- endif %}

  {= mods.pipe_delay =} #(
    .WIDTH (1),
    .DEPTH (ZERO_DELAY)
  ) u_zero_delay (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   (zd_zero),
    .q_o   (out_zero)
  );
{%- if sd > 0 %}

  // The sample's side_i beside the whole pipeline, on the same clock enable, so it reaches
  // the output register with its result.
  wire [SD-1:0] out_side;

  {= mods.pipe_delay =} #(
    .WIDTH (SD),
    .DEPTH (SIDE_DELAY)
  ) u_side_delay (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   (side_i),
    .q_o   (out_side)
  );
{%- endif %}

{%- if handshake %}
  // ---------------------------------------------------------------- flow control
  // A two-entry queue: head (the output registers) and skid. A result enters when the
  // pipeline delivers one (out_valid at an enabled edge); the head leaves with valid_o &&
  // ready_i. The pipeline may advance while the skid entry is free after this edge, so en_q
  // is the next skid state, inverted, registered: the queue can always take what the
  // pipeline delivers at the next enabled edge.
  wire         push, pop, take;
  wire         zero_in;
  wire [M-1:0] i_in;
  assign push    = en && out_valid;
  assign pop     = valid_q && ready_i;
  assign take    = !valid_q || pop;  // the head is free at this edge
  assign zero_in = out_zero;
  assign i_in    = out_zero ? {M{1'b0}} : out_i;
{%- if color %}
  wire [C-1:0] r_in, g_in, b_in;
  assign r_in = out_zero ? {C{1'b0}} : out_r;
  assign g_in = out_zero ? {C{1'b0}} : out_g;
  assign b_in = out_zero ? {C{1'b0}} : out_b;
{%- endif %}
{%- if sd > 0 %}
  wire [SD-1:0] side_in;
  assign side_in = out_side;
{%- endif %}

  reg         valid_q, skid_valid_q, en_q;
  reg         zero_q, skid_zero_q;
  reg [M-1:0] i_q, skid_i_q;
{%- if color %}
  reg [C-1:0] r_q, g_q, b_q, skid_r_q, skid_g_q, skid_b_q;
{%- endif %}
{%- if sd > 0 %}
  reg [SD-1:0] side_q, skid_side_q;
{%- endif %}
  wire        skid_valid_d;
  assign skid_valid_d = take ? (skid_valid_q && push) : (skid_valid_q || push);

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      valid_q      <= 1'b0;
      skid_valid_q <= 1'b0;
      en_q         <= 1'b0;  // ready_o low in reset, high from the first clock after it
    end else begin
      if (take) begin
        valid_q <= skid_valid_q || push;
      end
      skid_valid_q <= skid_valid_d;
      en_q         <= !skid_valid_d;
    end
  end

  always @(posedge clk_i) begin
    if (take) begin
      // The head takes the skid entry if there is one, else the new result.
      zero_q <= skid_valid_q ? skid_zero_q : zero_in;
      i_q    <= skid_valid_q ? skid_i_q : i_in;
{%- if color %}
      r_q    <= skid_valid_q ? skid_r_q : r_in;
      g_q    <= skid_valid_q ? skid_g_q : g_in;
      b_q    <= skid_valid_q ? skid_b_q : b_in;
{%- endif %}
{%- if sd > 0 %}
      side_q <= skid_valid_q ? skid_side_q : side_in;
{%- endif %}
    end
    if (push && (skid_valid_q || !take)) begin
      // The new result waits behind the head.
      skid_zero_q <= zero_in;
      skid_i_q    <= i_in;
{%- if color %}
      skid_r_q    <= r_in;
      skid_g_q    <= g_in;
      skid_b_q    <= b_in;
{%- endif %}
{%- if sd > 0 %}
      skid_side_q <= side_in;
{%- endif %}
    end
  end

  assign en      = en_q;
  assign ready_o = en_q;
{%- else %}
  reg         valid_q;
  reg         zero_q;
  reg [M-1:0] i_q;
{%- if color %}
  reg [C-1:0] r_q, g_q, b_q;
{%- endif %}

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      valid_q <= 1'b0;
    end else begin
      valid_q <= out_valid;
    end
  end

  always @(posedge clk_i) begin
    zero_q <= out_zero;
    i_q    <= out_zero ? {M{1'b0}} : out_i;
{%- if color %}
    r_q    <= out_zero ? {C{1'b0}} : out_r;
    g_q    <= out_zero ? {C{1'b0}} : out_g;
    b_q    <= out_zero ? {C{1'b0}} : out_b;
{%- endif %}
  end
{%- endif %}

  assign valid_o = valid_q;
  assign zero_o  = zero_q;
  assign i_o     = i_q;
{%- if color %}
  assign r_o     = r_q;
  assign g_o     = g_q;
  assign b_o     = b_q;
{%- endif %}
{%- if sd > 0 %}
  assign side_o  = side_q;
{%- endif %}

endmodule

`default_nettype wire
