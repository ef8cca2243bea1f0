{= h.header =}
`default_nettype none

// Reciprocal ROM: entry i holds round(2^(R-1+W) / m) for m = 2^(R-1) + i, clipped to W bits
// (contents: rmapgen's model, recip_rom::contents). The reduced max always has its MSB set,
// so the address is the R-1 bits below it. Read through a register so that it maps to block
// RAM. Latency 1.
{%- if dual %}
// Two read ports (a and b), each with its own enable, on one array: a true dual-port block
// RAM serves two lanes of rmap_lanes (rmapgen::stages::rmap_lanes::recip_read says which lane
// reads which port).
{%- endif %}
module {= h.module =}{= h.params =} (
{= h.ports =}
);

  localparam W       = {= w =};  // entry width
  localparam ENTRIES = {= entries =};  // 2^(R-1)

{%- if attrs %}
  // ram_style (--target {= target =}): block RAM even where Yosys would build a small table from
  // LUTs, so that every configuration has its ROM where rmapgen fpga checks for it.
  (* ram_style = "block" *)
{%- endif %}
  reg [W-1:0] rom [0:ENTRIES-1];
  initial begin
    $readmemh({= param =}, rom);
  end
{%- if dual %}

  reg [W-1:0] data_a_q, data_b_q;
  always @(posedge clk_i) begin
    if (en_a_i) begin
      data_a_q <= rom[addr_a_i];
    end
  end

  always @(posedge clk_i) begin
    if (en_b_i) begin
      data_b_q <= rom[addr_b_i];
    end
  end

  assign data_a_o = data_a_q;
  assign data_b_o = data_b_q;
{%- else %}

  reg [W-1:0] data_q;
  always @(posedge clk_i) begin
    if (en_i) begin
      data_q <= rom[addr_i];
    end
  end

  assign data_o = data_q;
{%- endif %}

endmodule

`default_nettype wire
