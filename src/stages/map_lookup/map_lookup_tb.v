{% extends "tb/base_tb.v" %}
{%- block description %}
//
// map_lookup splits each position into a base entry and a weight and reads the entries of
// the max axis's map from the banks (map_bank*.hex hold the scene's map in both buffers).
// Before streaming, this testbench writes the second map (map2_<axis>.hex) into buffer 1
// through the host port, with en_i random (writes do not depend on it); vectors with buf 1
// then expect the second map. The vectors cover position 0, POS_MAX and both sides of every
// base boundary in each lane, every axis, sign combination and buffer at the extreme
// corners, the gradient corners' positions, then random.
{%- endblock %}
{%- block decls %}
{%- include "tb/map2_decls.v" %}
{%- endblock %}
{%- block init %}
{%- include "tb/map2_init.v" %}
{%- endblock %}
{%- block preload %}

    // Load the second map into buffer 1; no output may appear meanwhile.
    wr_buf_i = 1'b1;
    while (nwr < NWRITES) begin
      @(negedge clk_i);
      if (valid_o !== 1'b0) protocol_error("valid_o during the map load");
      rnd = $random(seed);
      en_i = rnd[0];
      host_write;
    end
    @(negedge clk_i);
    wr_en_i = 1'b0;
{%- endblock %}
