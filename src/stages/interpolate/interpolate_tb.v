{% extends "tb/base_tb.v" %}
{%- block description %}
//
// interpolate blends four neighbours with weights in 0..S. The vectors cross weights 0, 1,
// S/2, S - 1 and S with extreme and mixed entries, then the gradient corners' look-ups, then
// random entries and weights.
{%- endblock %}
