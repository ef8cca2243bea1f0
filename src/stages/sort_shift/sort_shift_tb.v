{% extends "tb/base_tb.v" %}
{%- block description %}
//
// sort_shift finds the max axis (ties: lowest axis), splits off the signs and shifts the
// three magnitudes by the max's leading zeros before truncating them to red_bits. The
// vectors start with the zero vector, equal components, ties in each pair of axes, the most
// negative value in each position, magnitude 1, full-range maxima and every shift amount;
// the random ones draw the max's leading zeros uniformly, so every shift is well covered.
{%- endblock %}
