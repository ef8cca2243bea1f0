{% extends "tb/base_tb.v" %}
{%- block description %}
//
// linear_index scales each fraction to a position, round(u * POS_MAX / 2^F), the all-ones
// code going to POS_MAX. The vectors are exhaustive (every fraction code in both lanes),
// then random.
{%- endblock %}
