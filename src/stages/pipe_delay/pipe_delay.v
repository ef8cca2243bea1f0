{= h.header =}
`default_nettype none

// Delay line for sideband signals: q_o is d_i of DEPTH enabled clocks ago. Data only, no
// reset (valid bits travel through the stages themselves).
module {= h.module =} #(
  parameter WIDTH = 1,  // bits carried
  parameter DEPTH = 1   // clocks of delay, >= 1
) (
{= h.ports =}
);

  reg [WIDTH*DEPTH-1:0] line_q;  // newest sample in the low WIDTH bits

  generate
    if (DEPTH == 1) begin : g_one
      always @(posedge clk_i) begin
        if (en_i) begin
          line_q <= d_i;
        end
      end
    end else begin : g_many
      always @(posedge clk_i) begin
        if (en_i) begin
          line_q <= {line_q[WIDTH*(DEPTH-1)-1:0], d_i};
        end
      end
    end
  endgenerate

  assign q_o = line_q[WIDTH*DEPTH-1 -: WIDTH];

endmodule

`default_nettype wire
