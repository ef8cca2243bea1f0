{= h.header =}
`default_nettype none

// Normalise: u = a / m and v = b / m as F-bit fractions, computed as a * (1/m) with the
// reciprocal ROM and two multipliers, rounded half up:
//   u = min(2^F-1, (a*recip + 2^(SH-1)) >> SH).
// A component equal to the max saturates to all ones, which the index stages read as exactly
// 1. Stage 1 reads the ROM and compares; stage 2 multiplies by the two halves of a; stage 3
// adds the halves, rounds and saturates. Latency 3.
module normalise (
{= h.ports =}
);

  localparam R  = {= r =};  // reduced magnitude width
  localparam W  = {= w =};  // reciprocal width
  localparam F  = {= f =};  // fraction width
  localparam RA = {= ra =};  // reciprocal ROM address width
  localparam SH = {= sh =};  // a * recip >> SH is an F-bit fraction: R-1+W-F
  localparam PW = {= pw =};  // a * recip + HALF, never overflows
  localparam AL = {= al =};  // low part of a in the two-part multiply
  localparam [PW-1:0] HALF = {= pw =}'d{= half =};  // 2^(SH-1), rounds half up

  // ---------------------------------------------------------------- stage 1
  wire [W-1:0] recip_q1;  // registered inside the ROM
  recip_rom u_recip_rom (
    .clk_i  (clk_i),
    .en_i   (en_i),
    .addr_i (m_i[RA-1:0]),
    .data_o (recip_q1)
  );

  reg         valid_q1;
  reg [R-1:0] a_q1, b_q1;
  reg         a_max_q1, b_max_q1;

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      valid_q1 <= 1'b0;
    end else if (en_i) begin
      valid_q1 <= valid_i;
    end
  end

  always @(posedge clk_i) begin
    if (en_i) begin
      a_q1     <= a_i;
      b_q1     <= b_i;
      a_max_q1 <= (a_i == m_i);
      b_max_q1 <= (b_i == m_i);
    end
  end

  // ---------------------------------------------------------------- stage 2
  // a * recip in two halves of a, so that each half's adder tree fits in a clock; stage 3
  // adds them with the rounding constant.
  wire [PW-1:0] a_lo_x, a_hi_x, recip_x;
  assign a_lo_x  = {{(PW-AL){1'b0}}, a_q1[AL-1:0]};
  assign a_hi_x  = {{(PW-R+AL){1'b0}}, a_q1[R-1:AL]};
  assign recip_x = {{(PW-W){1'b0}}, recip_q1};
  wire [PW-1:0] b_lo_x, b_hi_x;
  assign b_lo_x  = {{(PW-AL){1'b0}}, b_q1[AL-1:0]};
  assign b_hi_x  = {{(PW-R+AL){1'b0}}, b_q1[R-1:AL]};

  reg          valid_q2;
  reg [PW-1:0] pa_lo_q2, pa_hi_q2, pb_lo_q2, pb_hi_q2;
  reg          a_max_q2, b_max_q2;

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      valid_q2 <= 1'b0;
    end else if (en_i) begin
      valid_q2 <= valid_q1;
    end
  end

  always @(posedge clk_i) begin
    if (en_i) begin
      pa_lo_q2 <= a_lo_x * recip_x;
      pa_hi_q2 <= a_hi_x * recip_x;
      pb_lo_q2 <= b_lo_x * recip_x;
      pb_hi_q2 <= b_hi_x * recip_x;
      a_max_q2 <= a_max_q1;
      b_max_q2 <= b_max_q1;
    end
  end

  // ---------------------------------------------------------------- stage 3
  wire [PW-1:0] sa, sb;
  assign sa = pa_lo_q2 + (pa_hi_q2 << AL) + HALF;
  assign sb = pb_lo_q2 + (pb_hi_q2 << AL) + HALF;

  // Anything at or above 2^F after the shift saturates.
  wire sat_a, sat_b;
  assign sat_a = a_max_q2 || (|sa[PW-1:SH+F]);
  assign sat_b = b_max_q2 || (|sb[PW-1:SH+F]);

  wire unused_round;
  assign unused_round = ^{sa[SH-1:0], sb[SH-1:0]};

  reg         valid_q3;
  reg [F-1:0] u_q3, v_q3;

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      valid_q3 <= 1'b0;
    end else if (en_i) begin
      valid_q3 <= valid_q2;
    end
  end

  always @(posedge clk_i) begin
    if (en_i) begin
      u_q3 <= sat_a ? {F{1'b1}} : sa[SH+F-1:SH];
      v_q3 <= sat_b ? {F{1'b1}} : sb[SH+F-1:SH];
    end
  end

  assign valid_o = valid_q3;
  assign u_o     = u_q3;
  assign v_o     = v_q3;

endmodule

`default_nettype wire
