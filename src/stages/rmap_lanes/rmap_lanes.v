{= h.header =}
`default_nettype none

// {= l =} lanes of {= top =}: {= l =} samples in and {= l =} results out per clock, in order. Every
// per-lane port packs lane k in bits [k*W+W-1 : k*W], W its width in {= top =}
// (rmapgen::stages::rmap_lanes); lane 0: {= packing =}.
{%- if roms.is_empty() %}
// Each lane is a whole {= top =} with its own ROMs and map banks. The host write port and
{%- else %}
// Two lanes share a reciprocal ROM, one true dual-port array: lane 2j reads port a and lane
// 2j+1 port b of {= rom =} u_recip_rom<j> (rmapgen::stages::rmap_lanes::recip_read), each
// on its own lane's enable, with its lane's latency.{% if odd %} The odd last lane has a ROM to itself.{% endif %}
// Every lane has its own compensation ROM (two reads a lane: both ports) and map banks (a host
// write and a read: both ports). The host write port and
{%- endif %}
// swap_i go to every lane, so the same writes load every lane's copy of a map and the lanes
// swap buffers in the same clock: the swap and write rules of {= top =} hold unchanged.
{%- if handshake %}
// Flow control for the whole beat: the beat (every lane with its valid_i bit) is accepted at
// a rising edge with |valid_i && ready_o, and its results leave together with |valid_o &&
// ready_i; valid_o is the beat's valid_i. Every lane takes the beat's valid and the same
// ready_i, so their pipeline enables, output queues and ready_o move in step; each lane's own
// valid bit travels beside its sample (side_i / side_o) and masks valid_o. Latency {= latency =}
// enabled clocks (clocks with ready_o high), plus any wait in the output queue.
{%- else %}
// No flow control: lane k's sample is accepted every clock valid_i[k] is high and its result
// leaves {= latency =} clocks later with valid_o[k]; lanes without a valid bit give no result.
{%- endif %}
module {= h.module =}{= h.params =} (
{= h.ports =}
);

{%- if handshake %}

  localparam L = {= l =};  // lanes

  // The beat's valid, taken by every lane; each lane's own bit rides on its side_i.
  wire beat_valid;
  assign beat_valid = |valid_i;

  wire [L-1:0] lane_ready;  // equal in every lane: their control inputs are the same
  wire [L-1:0] lane_valid;  // the beat's results are on the outputs
  wire [L-1:0] lane_side;   // the lane's valid bit of that beat
  wire [L-2:0] unused_lane_ready;  // lane 0's ready_o speaks for all
  assign unused_lane_ready = lane_ready[L-1:1];
  assign ready_o = lane_ready[0];
  assign valid_o = lane_valid & lane_side;
{%- endif %}
{%- if !roms.is_empty() %}

  // Each lane's read of its shared reciprocal ROM, packed like a per-lane port.
  wire [{= l - 1 =}:0]  recip_en;
  wire [{= l * ra - 1 =}:0] recip_addr;
  wire [{= l * rw - 1 =}:0] recip_data;
{%- if odd %}
  wire [{= rw - 1 =}:0]  unused_recip_data;  // the idle port b of the odd last lane's ROM
{%- endif %}
{%- for r in roms %}

  {= rom =}{= rom_params =} {= r.inst =} (
{%- for p in r.pins %}
    {= p =}{% if !loop.last %},{% endif %}
{%- endfor %}
  );
{%- endfor %}
{%- endif %}
{%- for lane in lanes %}

  {= top =}{= top_params =} {= lane.inst =} (
{%- for p in lane.pins %}
    {= p =}{% if !loop.last %},{% endif %}
{%- endfor %}
  );
{%- endfor %}

endmodule

`default_nettype wire
