{= h.header =}
`default_nettype none

// Linear index, in place of the atan ROM when distortion compensation is off: the position
// is the fraction scaled to 0..POS_MAX, p = (u * POS_MAX + 2^(F-1)) >> F (half up), and the
// all-ones code (tan = 1) goes to the border exactly: p = POS_MAX. Latency 1.
module linear_index (
{= h.ports =}
);

  localparam F   = {= f =};  // fraction width
  localparam POS = {= pos =};  // position width
  localparam LW  = {= lw =};  // u * POS_MAX + HALF
  localparam [POS-1:0] POS_MAX = {= pos =}'d{= pos_max =};  // (2^I - 1) * 2^P, the border
  localparam [LW-1:0]  HALF    = {= lw =}'d{= half =};  // 2^(F-1)

  wire [LW-1:0] u_x, v_x, scale;
  assign u_x   = {{POS{1'b0}}, u_i};
  assign v_x   = {{POS{1'b0}}, v_i};
  assign scale = {{F{1'b0}}, POS_MAX};

  wire [LW-1:0] su, sv;
  assign su = u_x * scale + HALF;
  assign sv = v_x * scale + HALF;

  wire unused_round;
  assign unused_round = ^{su[F-1:0], sv[F-1:0]};

  reg           valid_q;
  reg [POS-1:0] pu_q, pv_q;

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      valid_q <= 1'b0;
    end else if (en_i) begin
      valid_q <= valid_i;
    end
  end

  always @(posedge clk_i) begin
    if (en_i) begin
      pu_q <= (u_i == {F{1'b1}}) ? POS_MAX : su[LW-1:F];
      pv_q <= (v_i == {F{1'b1}}) ? POS_MAX : sv[LW-1:F];
    end
  end

  assign valid_o = valid_q;
  assign pu_o    = pu_q;
  assign pv_o    = pv_q;

endmodule

`default_nettype wire
