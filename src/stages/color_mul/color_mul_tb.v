{% extends "tb/base_tb.v" %}
{%- block description %}
//
// color_mul scales an 8-bit colour by the intensity, round(c * i / (2^M - 1)). The vectors
// cross intensities 0, 1, half, max - 1 and max with black, white and mixed colours, then
// every intensity once, then random (0 and 255 drawn more often).
{%- endblock %}
