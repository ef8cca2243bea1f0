{% extends "tb/base_tb.v" %}
{%- block description %}
//
// zero_detect flags an all-zero gradient. The vectors put the zero vector first, then each
// component alone at 1, -1, the most negative and the most positive value, every gradient
// corner of sort_shift, and random gradients whose components are zero half of the time.
{%- endblock %}
