{= h.header =}
`default_nettype none

// Distortion compensation (atan) ROM: turns a normalised fraction u = tan(angle) into a map
// position, so that equal position steps are equal steps in angle: entry u holds
// round(atan(u / 2^F) / (pi/4) * POS_MAX), the all-ones code standing for tan = 1
// (contents: rmapgen's model, atan_rom::contents). u and v each read their own copy of the
// table, so each is a single-port synchronous ROM that maps to its own block RAM. Latency 1.
module atan_rom #(
  parameter INIT_FILE = "{= init_file =}"  // $readmemh file, one POS-bit entry per line
) (
{= h.ports =}
);

  localparam POS     = {= pos =};  // position width, index and interpolation bits
  localparam ENTRIES = {= entries =};  // 2^F, one per fraction code

  reg [POS-1:0] rom_u [0:ENTRIES-1];
  reg [POS-1:0] rom_v [0:ENTRIES-1];
  initial begin
    $readmemh(INIT_FILE, rom_u);
    $readmemh(INIT_FILE, rom_v);
  end

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
      pu_q <= rom_u[u_i];
    end
  end

  always @(posedge clk_i) begin
    if (en_i) begin
      pv_q <= rom_v[v_i];
    end
  end

  assign valid_o = valid_q;
  assign pu_o    = pu_q;
  assign pv_o    = pv_q;

endmodule

`default_nettype wire
