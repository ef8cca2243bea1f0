{% extends "tb/base_tb.v" %}
{%- block description %}
//
// atan_rom maps each fraction through the compensation ROM (atan_rom.hex). The vectors are
// exhaustive (every fraction code in both lanes: 0, all ones and every step of the ROM),
// then random.
{%- endblock %}
