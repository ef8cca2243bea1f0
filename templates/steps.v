{%- for s in steps %}

  // ---------------------------------------------------------------- {= s.title =}
{%- for n in s.nodes %}
  wire {= n.range =} {= n.name =}_d;
{%- endfor %}
{%- for n in s.nodes %}
  assign {= n.name =}_d = {= n.expr =};
{%- endfor %}
{%- if !s.unused.is_empty() %}

  // Bits the bounded sum does not need: its value fits, so they cancel modulo its width.
  wire unused_{= s.nodes[0].name =};
  assign unused_{= s.nodes[0].name =} = ^{{= s.unused.join(", ") =}};
{%- endif %}
{%- if s.registered %}
{% for n in s.nodes %}
  reg  {= n.range =} {= n.name =}_q;
{%- endfor %}

  always @(posedge clk_i) begin
    if (en_i) begin
{%- for n in s.nodes %}
      {= n.name =}_q <= {= n.name =}_d;
{%- endfor %}
    end
  end
{%- endif %}
{%- endfor %}
