{= h.header =}
`default_nettype none

// Distortion compensation (atan) ROM: turns a normalised fraction u = tan(angle) into a map
// position, so that equal position steps are equal steps in angle: entry u holds
// round(atan(u / 2^F) / (pi/4) * POS_MAX), the all-ones code standing for tan = 1
// (contents: rmapgen's model, atan_rom::contents).{% if ice40 %} u and v each read their own copy of the
// table (--target ice40), so each is a single-port synchronous ROM that maps to its own block
// RAM.{% else %} u and v read one table through two synchronous read ports
// (a true dual-port block RAM where the device has one).{% endif %}{% if out_reg %} A fabric
// register follows the block RAM's output register (pipeline_depth >= 1).{% endif %} Latency {= latency =}.
module {= h.module =}{= h.params =} (
{= h.ports =}
);

  localparam POS     = {= pos =};  // position width, index and interpolation bits
  localparam ENTRIES = {= entries =};  // 2^F, one per fraction code
  localparam LATENCY = {= latency =};

{%- if ice40 %}
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
