{= h.header =}
`default_nettype none

// Zero detect: flags a gradient whose three components are all zero. Such a gradient has no
// direction; the top forces its intensity (and colour) to zero and raises zero_o.
// Latency 1.
module {= h.module =} (
{= h.ports =}
);

  localparam G = {= g =};  // gradient component width

  wire zero_d;
  assign zero_d = (gx_i == {G{1'b0}}) && (gy_i == {G{1'b0}}) && (gz_i == {G{1'b0}});

  reg valid_q;
  reg zero_q;

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      valid_q <= 1'b0;
    end else if (en_i) begin
      valid_q <= valid_i;
    end
  end

  always @(posedge clk_i) begin
    if (en_i) begin
      zero_q <= zero_d;
    end
  end

  assign valid_o = valid_q;
  assign zero_o  = zero_q;

endmodule

`default_nettype wire
