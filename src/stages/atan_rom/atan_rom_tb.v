{% extends "tb/base_tb.v" %}
{%- block description %}
//
{%- if t.map2_params.is_empty() %}
// atan_rom maps each fraction through the compensation ROM (atan_rom.hex). The vectors are
// exhaustive (every fraction code in both lanes: 0, all ones and every step of the ROM),
// then random.
{%- else %}
// atan_rom maps each fraction through the compensation table of the sample's buffer (both
// hold the scene's table out of reset). Before streaming, this testbench writes the second
// map and table (map2_<axis>.hex, map2_table.hex) through the host port, with en_i random
// (writes do not depend on it): the stage takes the table's writes (axis slot 3) into
// buffer 1, and vectors with buf 1 then expect the second table. The vectors are exhaustive
// (every fraction code in both lanes, in each buffer), then random.
{%- endif %}
{%- endblock %}
{%- block decls %}
{%- if !t.map2_params.is_empty() %}
{%- include "tb/map2_decls.v" %}
{%- endif %}
{%- endblock %}
{%- block init %}
{%- if !t.map2_params.is_empty() %}
{%- include "tb/map2_init.v" %}
{%- endif %}
{%- endblock %}
{%- block preload %}
{%- if !t.map2_params.is_empty() %}
{%- include "tb/map2_preload.v" %}
{%- endif %}
{%- endblock %}
