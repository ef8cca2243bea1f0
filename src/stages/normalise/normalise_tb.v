{% extends "tb/base_tb.v" %}
{%- block description %}
//
// normalise divides a and b by m with the reciprocal ROM (recip_rom.hex) and two
// multipliers. The vectors cover the zero vector (m = a = b = 0), both ends of the ROM with
// a and b at 0, 1, half, m - 1 and m, every ROM entry once, the gradient corners as they
// reach this stage, then random m with a, b in 0..=m.
{%- endblock %}
