{= h.header =}
`default_nettype none
{%- if ram %}

// Distortion compensation table, loaded by the host (comp_table = ram): turns a normalised
// fraction u = tan(angle) into a map position. Two buffers, as the maps have: a sample reads
// the buffer it was accepted with (rd_buf_i), the host writes the other through the map write
// port, axis slot 3, address u, data the position (the maps' slots 0..2 are not for this
// stage). Out of reset both buffers hold the scene's table ({= param =}, address {buf, u}).
// u and v each read their own copy, and every write goes to both, so each copy is a simple
// dual-port RAM (one read, one write port) that maps to its own block RAM. A read and a write
// of the same address in one cycle never happen: samples read the front buffer.{% if out_reg %} A
// fabric register follows the block RAM's output register (pipeline_depth >= 1).{% endif %}
// Latency {= latency =}.
module {= h.module =}{= h.params =} (
{= h.ports =}
);

  localparam POS     = {= pos =};  // position width, index and interpolation bits
  localparam F       = {= f =};  // fraction width: a table address
  localparam A       = {= a =};  // map write address width
  localparam M       = {= m =};  // map write data width
  localparam ENTRIES = {= entries =};  // 2^F per buffer
  localparam LATENCY = {= latency =};

  (* no_rw_check, ram_style = "block" *)
  reg [POS-1:0] ram_u [0:2*ENTRIES-1];
  (* no_rw_check, ram_style = "block" *)
  reg [POS-1:0] ram_v [0:2*ENTRIES-1];
  initial begin
    $readmemh({= param =}, ram_u);
    $readmemh({= param =}, ram_v);
  end

  // Slot 3 of the write port is the table; the address and data bits above a table entry's
  // are not read.
  wire table_we;
  assign table_we = wr_en_i && (wr_axis_i == 2'd3);
{%- if a > f %}
  wire unused_wr_addr;
  assign unused_wr_addr = ^wr_addr_i[A-1:F];
{%- endif %}
{%- if m > pos %}
  wire unused_wr_data;
  assign unused_wr_data = ^wr_data_i[M-1:POS];
{%- endif %}

  always @(posedge clk_i) begin
    if (table_we) begin
      ram_u[{wr_buf_i, wr_addr_i[F-1:0]}] <= wr_data_i[POS-1:0];
      ram_v[{wr_buf_i, wr_addr_i[F-1:0]}] <= wr_data_i[POS-1:0];
    end
  end

  reg [POS-1:0] pu_q, pv_q;

  always @(posedge clk_i) begin
    if (en_i) begin
      pu_q <= ram_u[{rd_buf_i, u_i}];
    end
  end

  always @(posedge clk_i) begin
    if (en_i) begin
      pv_q <= ram_v[{rd_buf_i, v_i}];
    end
  end
{%- else %}

// Distortion compensation (atan) ROM: turns a normalised fraction u = tan(angle) into a map
// position, so that equal position steps are equal steps in angle: entry u holds
// round(atan(u / 2^F) / (pi/4) * POS_MAX), the all-ones code standing for tan = 1
// (contents: rmapgen's model, atan_rom::contents).{% if copies %} u and v each read their own copy of the
// table (--target {= target =}), so each is a single-port synchronous ROM that maps to its own block
// RAM.{% else %} u and v read one table through two synchronous read ports
// (a true dual-port block RAM where the device has one).{% endif %}{% if out_reg %} A fabric
// register follows the block RAM's output register (pipeline_depth >= 1).{% endif %} Latency {= latency =}.
module {= h.module =}{= h.params =} (
{= h.ports =}
);

  localparam POS     = {= pos =};  // position width, index and interpolation bits
  localparam ENTRIES = {= entries =};  // 2^F, one per fraction code
  localparam LATENCY = {= latency =};

{%- if copies %}
  // ram_style: block RAM even where Yosys would build a small table from LUTs.
  (* ram_style = "block" *)
  reg [POS-1:0] rom_u [0:ENTRIES-1];
  (* ram_style = "block" *)
  reg [POS-1:0] rom_v [0:ENTRIES-1];
  initial begin
    $readmemh({= param =}, rom_u);
    $readmemh({= param =}, rom_v);
  end
{%- else %}
{%- if attrs %}
  // ram_style (--target {= target =}): block RAM even where Yosys would build a small table
  // from LUTs; u and v are its two read ports.
  (* ram_style = "block" *)
{%- endif %}
  reg [POS-1:0] rom [0:ENTRIES-1];
  initial begin
    $readmemh({= param =}, rom);
  end
{%- endif %}

  reg [POS-1:0] pu_q, pv_q;

  always @(posedge clk_i) begin
    if (en_i) begin
      pu_q <= {= rom_u =}[u_i];
    end
  end

  always @(posedge clk_i) begin
    if (en_i) begin
      pv_q <= {= rom_v =}[v_i];
    end
  end
{%- endif %}

{%- if out_reg %}

  reg [POS-1:0] pu_q2, pv_q2;

  always @(posedge clk_i) begin
    if (en_i) begin
      pu_q2 <= pu_q;
      pv_q2 <= pv_q;
    end
  end
{%- endif %}
{%- include "valid_line.v" %}
{%- if out_reg %}
  assign pu_o    = pu_q2;
  assign pv_o    = pv_q2;
{%- else %}
  assign pu_o    = pu_q;
  assign pv_o    = pv_q;
{%- endif %}

endmodule

`default_nettype wire
