{= h.header =}
`default_nettype none

// Colour multiply: each 8-bit channel of the sample colour times the intensity, scaled so
// that full intensity keeps the colour: round(c * i / D), half up, D = 2^M - 1. The division
// by the constant 2D is a multiply by K and a shift by S (exact for every input; see
// rmapgen's model, color_mul::constants): out = ((2*c*i + D) * K) >> S.
// Stage 1 forms the numerators; stage 2 multiplies by K and shifts. Latency 2.
module color_mul (
{= h.ports =}
);

  localparam M  = {= m =};  // intensity width
  localparam C  = {= c =};  // colour channel width
  localparam NW = {= nw =};  // numerator 2*c*i + D
  localparam S  = {= s =};  // shift of the constant division
  localparam PW = {= pw =};  // numerator * K; the quotient (<= 255) sits above S
  localparam [NW-1:0] D = {= nw =}'d{= d =};  // 2^M - 1
  localparam [PW-1:0] K = {= pw =}'d{= k =};  // ceil(2^S / 2D)

  // ---------------------------------------------------------------- stage 1
  wire [NW-1:0] i_x, r_x, g_x, b_x;
  assign i_x = {{(NW-M){1'b0}}, i_i};
  assign r_x = {{(NW-C-1){1'b0}}, r_i, 1'b0};  // 2 * r
  assign g_x = {{(NW-C-1){1'b0}}, g_i, 1'b0};
  assign b_x = {{(NW-C-1){1'b0}}, b_i, 1'b0};

  reg          valid_q1;
  reg [NW-1:0] nr_q1, ng_q1, nb_q1;

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      valid_q1 <= 1'b0;
    end else if (en_i) begin
      valid_q1 <= valid_i;
    end
  end

  always @(posedge clk_i) begin
    if (en_i) begin
      nr_q1 <= r_x * i_x + D;
      ng_q1 <= g_x * i_x + D;
      nb_q1 <= b_x * i_x + D;
    end
  end

  // ---------------------------------------------------------------- stage 2
  wire [PW-1:0] pr, pg, pb;
  assign pr = {{(PW-NW){1'b0}}, nr_q1} * K;
  assign pg = {{(PW-NW){1'b0}}, ng_q1} * K;
  assign pb = {{(PW-NW){1'b0}}, nb_q1} * K;

  wire unused_low;
  assign unused_low = ^{pr[S-1:0], pg[S-1:0], pb[S-1:0]};

  reg         valid_q2;
  reg [C-1:0] r_q2, g_q2, b_q2;

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      valid_q2 <= 1'b0;
    end else if (en_i) begin
      valid_q2 <= valid_q1;
    end
  end

  always @(posedge clk_i) begin
    if (en_i) begin
      r_q2 <= pr[PW-1:S];
      g_q2 <= pg[PW-1:S];
      b_q2 <= pb[PW-1:S];
    end
  end

  assign valid_o = valid_q2;
  assign r_o     = r_q2;
  assign g_o     = g_q2;
  assign b_o     = b_q2;

endmodule

`default_nettype wire
