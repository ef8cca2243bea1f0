{% extends "tb/base_tb.v" %}
{%- block description %}
//
// rmap_top: the whole pipeline. The vectors come in two parts: `map` 0, shaded with the
// scene's map the design holds from reset, then `map` 1, shaded with the second map. While
// the map-0 part streams, this testbench writes map2_<axis>.hex through the host port into
// the back buffer (three clocks in four, interleaved with the samples); the first map-1
// vector waits until the load is complete and is presented with swap_i high (a swap takes
// effect for the sample accepted in the same clock). The mid-stream reset comes before the
// swap. zero_o is checked with the intensity{% if t.fields.len() > 6 %} and the colour{% endif %}.
{%- endblock %}
{%- block decls %}
{%- include "tb/map2_decls.v" %}
  reg swapped;  // swap_i has been pulsed
{%- endblock %}
{%- block init %}
{%- include "tb/map2_init.v" %}
    swapped = 1'b0;
{%- endblock %}
{%- block reset_quiet %}
        wr_en_i = 1'b0;
        swap_i = 1'b0;
        if (swapped) $fatal(1, "the mid-stream reset must come before the swap");
{%- endblock %}
{%- block hold %}

      // The first map-1 vector waits for the second map to be loaded.
      swap_i = 1'b0;
      if (present && !swapped && v_map[nin[DL-1:0]] == 1'b1 && nwr < NWRITES) present = 1'b0;
{%- endblock %}
{%- block accept %}
          if (v_map[si] == 1'b1 && !swapped) begin
            swap_i = 1'b1;
            swapped = 1'b1;
            $display("swap with line %0d, after %0d host writes", v_line[si], nwr);
          end
          if (v_map[si] == 1'b0 && swapped) begin
            $fatal(1, "%0s line %0d: a map-0 vector after the swap", vector_file, v_line[si]);
          end
{%- endblock %}
{%- block host %}

      // Host writes into the back buffer, three clocks in four, never in the swap's clock.
      wr_en_i = 1'b0;
      if (nwr < NWRITES && !swap_i) begin
        rnd = $random(seed);
        if (rnd[1:0] != 2'b00) host_write;
      end
{%- endblock %}
{%- block finish %}
    if (!swapped) protocol_error("no map-1 vector: the buffer swap was not tested");
{%- endblock %}
