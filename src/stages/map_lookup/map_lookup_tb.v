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
{%- include "tb/map2_preload.v" %}
{%- endblock %}
