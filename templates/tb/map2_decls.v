

  // The second map (map2_<axis>.hex, logical address order), written through the host port.
  localparam MAP_ENTRIES = {= t.map_entries =};  // per axis, 2^A
  localparam A           = {= t.map_addr_bits =};  // logical map address bits
{%- if t.table_entries > 0 %}
  localparam TABLE_ENTRIES = {= t.table_entries =};  // the compensation table, 2^F, after the maps (axis slot 3)
  localparam NWRITES     = {= t.nwrites =};  // all three axis maps and the table
{%- else %}
  localparam NWRITES     = {= t.nwrites =};  // all three axis maps
{%- endif %}
  reg [{= t.map_bits - 1 =}:0] map2 [0:NWRITES-1];
  integer     nwr;  // host writes issued
  reg [A+1:0] wi;

  // Host write number nwr: entry nwr mod 2^A of the map of axis nwr / 2^A.
  task host_write;
    begin
      wi = nwr[A+1:0];
      wr_en_i = 1'b1;
      wr_axis_i = wi[A+1:A];
      wr_addr_i = wi[A-1:0];
      wr_data_i = map2[wi];
      nwr = nwr + 1;
    end
  endtask
