{= h.header =}
`default_nettype none

// Reciprocal ROM: entry i holds round(2^(R-1+W) / m) for m = 2^(R-1) + i, clipped to W bits
// (contents: rmapgen's model, recip_rom::contents). The reduced max always has its MSB set,
// so the address is the R-1 bits below it. Read through a register so that it maps to block
// RAM. Latency 1.
module {= h.module =}{= h.params =} (
{= h.ports =}
);

  localparam W       = {= w =};  // entry width
  localparam ENTRIES = {= entries =};  // 2^(R-1)

{%- if ice40 %}
  // ram_style (--target ice40): block RAM even where Yosys would build a small table from
  // LUTs, so that every configuration has its ROM where rmapgen fpga checks for it.
  (* ram_style = "block" *)
{%- endif %}
  reg [W-1:0] rom [0:ENTRIES-1];
  initial begin
    $readmemh({= param =}, rom);
  end

  reg [W-1:0] data_q;
  always @(posedge clk_i) begin
    if (en_i) begin
      data_q <= rom[addr_i];
    end
  end

  assign data_o = data_q;

endmodule

`default_nettype wire
