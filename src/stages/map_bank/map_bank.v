{= h.header =}
`default_nettype none

// One reflectance-map RAM bank: simple dual port, a synchronous write port for the host and
// a read port through a register, so that it maps to block RAM. Initialised from INIT_FILE
// (both buffers hold the scene's map), so the design shades out of reset. A read and a write
// of the same address in one cycle return undefined data; the top never issues one, because
// samples read the front buffer and the host writes the back one. Latency 1.
module {= h.module =}{= h.params =} (
{= h.ports =}
);

  localparam M       = {= m =};  // entry width
  localparam ENTRIES = {= entries =};  // 2^BA

{%- if attrs %}
  // no_rw_check (--target {= target =}): a same-address read and write never happen (see above), so
  // Yosys need not add logic to define their result. ram_style: block RAM at every size.
  (* no_rw_check, ram_style = "block" *)
{%- endif %}
  reg [M-1:0] mem [0:ENTRIES-1];
  initial begin
    $readmemh({= param =}, mem);
  end

  always @(posedge clk_i) begin
    if (wr_en_i) begin
      mem[wr_addr_i] <= wr_data_i;
    end
  end

  reg [M-1:0] rd_data_q;
  always @(posedge clk_i) begin
    if (en_i) begin
      rd_data_q <= mem[rd_addr_i];
    end
  end

  assign rd_data_o = rd_data_q;

endmodule

`default_nettype wire
