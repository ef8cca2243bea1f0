{= h.header =}
`default_nettype none

{% if interpolation -%}
// Map look-up: split each position into a base entry and an interpolation weight, and read
// the base entry and its three higher neighbours from the map of the max axis in one clock.
// The map is split into four banks by the parities of (i_u, i_v), so the four neighbours
// always sit in four different banks. Bank address {buf, axis, s_max, s_u, i_u >> 1, s_v,
// i_v >> 1}; the sample's rd_buf picks the buffer. The host writes through wr_* (logical map
// address, any buffer) independently of en_i.
// Stage 1 splits and forms the bank addresses; stage 2 reads the banks;{% if bank_reg %} stage 3 registers
// the banks' outputs in the fabric (pipeline_depth >= 1);{% endif %} stage {= out =} puts the bank outputs
// back in neighbour order. Latency {= latency =}.
{%- else -%}
// Map look-up without interpolation: the position is the entry index; read that entry from
// the map of the max axis. One bank, address {buf, axis, s_max, s_u, i_u, s_v, i_v}; the
// sample's rd_buf picks the buffer. The host writes through wr_* (logical map address, any
// buffer) independently of en_i.
// Stage 1 forms the bank address; stage 2 reads the bank;{% if bank_reg %} stage 3 registers the bank's
// output in the fabric (pipeline_depth >= 1);{% endif %} stage {= out =} registers the entry. Latency {= latency =}.
{%- endif %}
module {= h.module =}{= h.params =} (
{= h.ports =}
);

{%- if interpolation %}
  localparam I  = {= i =};  // entry index bits per component
  localparam P  = {= p =};  // interpolation weight fraction bits
  localparam IH = {= ih =};  // index bits inside a bank, i >> 1
{%- endif %}
  localparam BA = {= ba =};  // bank address width
  localparam M  = {= m =};  // entry width
  localparam LATENCY = {= latency =};
{%- if interpolation %}
  localparam [I-1:0]  BASE_MAX = {= i =}'d{= base_max =};  // 2^I - 2: the outer entry is never a base
  localparam [IH-1:0] HI_ONE   = {= ih =}'d1;

  // ---------------------------------------------------------------- stage 1
  // base = min(p >> P, 2^I - 2) and w = p - base * 2^P. Only the outer entry is clipped,
  // and then w = 2^P + (p mod 2^P).
  wire [I-1:0] idx_u, idx_v;
  wire [P-1:0] frac_u, frac_v;
  assign {idx_u, frac_u} = pu_i;
  assign {idx_v, frac_v} = pv_i;

  wire outer_u, outer_v;
  assign outer_u = (idx_u == {I{1'b1}});
  assign outer_v = (idx_v == {I{1'b1}});

  wire [I-1:0] base_u, base_v;
  assign base_u = outer_u ? BASE_MAX : idx_u;
  assign base_v = outer_v ? BASE_MAX : idx_v;

  // Of base and base + 1, the odd entry sits at base >> 1 in its bank and the even one at
  // (base + 1) >> 1, which is one more when base is odd.
  wire [IH-1:0] odd_u, odd_v, even_u, even_v;
  assign odd_u  = base_u[I-1:1];
  assign odd_v  = base_v[I-1:1];
  assign even_u = base_u[0] ? odd_u + HI_ONE : odd_u;
  assign even_v = base_v[0] ? odd_v + HI_ONE : odd_v;

  reg [BA-1:0] addr00_q1, addr10_q1, addr01_q1, addr11_q1;  // bank <u parity><v parity>
  reg          odd_u_q1, odd_v_q1;  // base parities, to put the banks back in order
  reg [P:0]    wu_q1, wv_q1;

  always @(posedge clk_i) begin
    if (en_i) begin
      addr00_q1 <= {rd_buf_i, axis_i, s_max_i, s_u_i, even_u, s_v_i, even_v};
      addr10_q1 <= {rd_buf_i, axis_i, s_max_i, s_u_i, odd_u,  s_v_i, even_v};
      addr01_q1 <= {rd_buf_i, axis_i, s_max_i, s_u_i, even_u, s_v_i, odd_v};
      addr11_q1 <= {rd_buf_i, axis_i, s_max_i, s_u_i, odd_u,  s_v_i, odd_v};
      odd_u_q1  <= base_u[0];
      odd_v_q1  <= base_v[0];
      wu_q1     <= {outer_u, frac_u};
      wv_q1     <= {outer_v, frac_v};
    end
  end

  // ---------------------------------------------------------------- host writes
  wire         wr_s_max, wr_s_u, wr_s_v;
  wire [I-1:0] wr_iu, wr_iv;
  assign {wr_s_max, wr_s_u, wr_iu, wr_s_v, wr_iv} = wr_addr_i;

  wire [BA-1:0] wr_bank_addr;
  assign wr_bank_addr = {wr_buf_i, wr_axis_i, wr_s_max, wr_s_u, wr_iu[I-1:1], wr_s_v, wr_iv[I-1:1]};

  // ---------------------------------------------------------------- stage 2
  wire [M-1:0] d00_q2, d10_q2, d01_q2, d11_q2;  // registered inside the banks
{% for b in banks %}
  {= bank =} #(
    .INIT_FILE ({= b.param =})
  ) {= b.inst =} (
    .clk_i     (clk_i),
    .en_i      (en_i),
    .rd_addr_i (addr{= b.name =}_q1),
    .wr_en_i   (wr_en_i && (wr_iu[0] == 1'b{= b.pu =}) && (wr_iv[0] == 1'b{= b.pv =})),
    .wr_addr_i (wr_bank_addr),
    .wr_data_i (wr_data_i),
    .rd_data_o (d{= b.name =}_q2)
  );
{% endfor %}
  reg       odd_u_q2, odd_v_q2;
  reg [P:0] wu_q2, wv_q2;

  always @(posedge clk_i) begin
    if (en_i) begin
      odd_u_q2 <= odd_u_q1;
      odd_v_q2 <= odd_v_q1;
      wu_q2    <= wu_q1;
      wv_q2    <= wv_q1;
    end
  end
{%- if bank_reg %}

  // ---------------------------------------------------------------- stage 3
  // The block RAMs' clock-to-output is slow; the neighbour reorder starts from a register.
  reg [M-1:0] d00_{= rd =}, d10_{= rd =}, d01_{= rd =}, d11_{= rd =};
  reg         odd_u_{= rd =}, odd_v_{= rd =};
  reg [P:0]   wu_{= rd =}, wv_{= rd =};

  always @(posedge clk_i) begin
    if (en_i) begin
      d00_{= rd =}   <= d00_q2;
      d10_{= rd =}   <= d10_q2;
      d01_{= rd =}   <= d01_q2;
      d11_{= rd =}   <= d11_q2;
      odd_u_{= rd =} <= odd_u_q2;
      odd_v_{= rd =} <= odd_v_q2;
      wu_{= rd =}    <= wu_q2;
      wv_{= rd =}    <= wv_q2;
    end
  end
{%- endif %}

  // ---------------------------------------------------------------- stage {= out =}
  // The base entry is in the bank of the base's parities, its u neighbour in the bank of the
  // other u parity, and so on.
  reg [M-1:0] e00_d, e10_d, e01_d, e11_d;
  always @* begin
    case ({odd_u_{= rd =}, odd_v_{= rd =}})
      2'b00: begin
        e00_d = d00_{= rd =};  e10_d = d10_{= rd =};  e01_d = d01_{= rd =};  e11_d = d11_{= rd =};
      end
      2'b10: begin
        e00_d = d10_{= rd =};  e10_d = d00_{= rd =};  e01_d = d11_{= rd =};  e11_d = d01_{= rd =};
      end
      2'b01: begin
        e00_d = d01_{= rd =};  e10_d = d11_{= rd =};  e01_d = d00_{= rd =};  e11_d = d10_{= rd =};
      end
      default: begin
        e00_d = d11_{= rd =};  e10_d = d01_{= rd =};  e01_d = d10_{= rd =};  e11_d = d00_{= rd =};
      end
    endcase
  end

  reg [M-1:0] e00_{= out_q =}, e10_{= out_q =}, e01_{= out_q =}, e11_{= out_q =};
  reg [P:0]   wu_{= out_q =}, wv_{= out_q =};

  always @(posedge clk_i) begin
    if (en_i) begin
      e00_{= out_q =} <= e00_d;
      e10_{= out_q =} <= e10_d;
      e01_{= out_q =} <= e01_d;
      e11_{= out_q =} <= e11_d;
      wu_{= out_q =}  <= wu_{= rd =};
      wv_{= out_q =}  <= wv_{= rd =};
    end
  end
{%- include "valid_line.v" %}
  assign e00_o   = e00_{= out_q =};
  assign e10_o   = e10_{= out_q =};
  assign e01_o   = e01_{= out_q =};
  assign e11_o   = e11_{= out_q =};
  assign wu_o    = wu_{= out_q =};
  assign wv_o    = wv_{= out_q =};
{%- else %}

  // ---------------------------------------------------------------- stage 1
  reg [BA-1:0] addr_q1;

  always @(posedge clk_i) begin
    if (en_i) begin
      addr_q1 <= {rd_buf_i, axis_i, s_max_i, s_u_i, pu_i, s_v_i, pv_i};
    end
  end

  // ---------------------------------------------------------------- stage 2
  wire [M-1:0] d_q2;  // registered inside the bank
{% for b in banks %}
  {= bank =} #(
    .INIT_FILE ({= b.param =})
  ) {= b.inst =} (
    .clk_i     (clk_i),
    .en_i      (en_i),
    .rd_addr_i (addr_q1),
    .wr_en_i   (wr_en_i),
    .wr_addr_i ({wr_buf_i, wr_axis_i, wr_addr_i}),
    .wr_data_i (wr_data_i),
    .rd_data_o (d_q2)
  );
{% endfor %}

{%- if bank_reg %}

  // ---------------------------------------------------------------- stage 3
  // The block RAM's clock-to-output is slow: a fabric register follows it.
  reg [M-1:0] d_{= rd =};

  always @(posedge clk_i) begin
    if (en_i) begin
      d_{= rd =} <= d_q2;
    end
  end
{%- endif %}

  // ---------------------------------------------------------------- stage {= out =}
  reg [M-1:0] e00_{= out_q =};

  always @(posedge clk_i) begin
    if (en_i) begin
      e00_{= out_q =} <= d_{= rd =};
    end
  end
{%- include "valid_line.v" %}
  assign e00_o   = e00_{= out_q =};
{%- endif %}

endmodule

`default_nettype wire
