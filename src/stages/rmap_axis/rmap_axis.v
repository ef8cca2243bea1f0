{= h.header =}
`default_nettype none

// AXI4-Stream top: {= top =} (the valid/ready top) with AXI4-Stream ports. A sample is
// accepted at a rising edge with s_axis_tvalid && s_axis_tready; its result leaves with
// m_axis_tvalid && m_axis_tready, {= latency =} clocks with s_axis_tready high after it at the
// earliest, and holds until then. tuser and tlast are not interpreted: they travel through
// {= top =}'s side_i / side_o beside the sample (on the pipeline's clock enable and through
// its output queue), so every result carries those of its own sample. No TKEEP / TSTRB: every
// byte of tdata is valid. tdata fields start on byte boundaries (rmapgen::stages::rmap_axis):
//   s_axis_tdata, {= s_slots.len() =} fields:{% for s in s_slots %} {= s.field =} {= s.range() =}{% endfor %}
//   m_axis_tdata, {= m_slots.len() =} fields:{% for s in m_slots %} {= s.field =} {= s.range() =}{% endfor %}
// Input padding bits are ignored (a sign extension of the gradients is fine); output padding
// bits are 0.
module {= h.module =}{= h.params =} (
{= h.ports =}
);
{%- if let Some((bits, pad)) = s_pad %}

  // The padding of s_axis_tdata: read by nothing.
  wire [{= bits - 1 =}:0] unused_s_pad;
  assign unused_s_pad = {= pad =};
{%- endif %}
{%- if !m_pads.is_empty() %}

  // The padding of m_axis_tdata.
{%- for (hi, lo) in m_pads %}
  assign m_axis_tdata[{% if hi == lo %}{= hi =}{% else %}{= hi =}:{= lo =}{% endif %}] = {= hi - lo + 1 =}'d0;
{%- endfor %}
{%- endif %}

  {= top =}{= top_params =} {= inst =} (
{%- for p in pins %}
    {= p =}{% if !loop.last %},{% endif %}
{%- endfor %}
  );

endmodule

`default_nettype wire
