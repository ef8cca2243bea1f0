{= h.header =}
`default_nettype none

{% if wishbone -%}
// Bus top: {= inner =} with a Wishbone B4 classic slave (32-bit data, word addresses
// wb_adr_i = byte offset / 4, as LiteX's SoC bus; {= span =} bytes) in front of its register
// block {= regs =}, which writes the maps through the host write port and swaps them at
// frame boundaries (docs/SOC.md). An access (wb_cyc_i && wb_stb_i) is answered by wb_ack_o,
// or wb_err_o when it is refused, for one clock; both are registers, so an access takes two
// clocks at least (a window write waits while a swap is pending or the pipeline drains).
// wb_dat_o holds the read data with wb_ack_o. wb_sel_i must be all ones for a write.
{%- else -%}
// Bus top: {= inner =} with an AXI4-Lite slave (32-bit data, byte addresses; {= span =}
// bytes) in front of its register block {= regs =}, which writes the maps through the host
// write port and swaps them at frame boundaries (docs/SOC.md). One transaction at a time,
// writes first: a write takes AW and W together, both ready for one clock when it is done,
// then B; a read takes AR when it is done, then R. A refused access answers SLVERR (BRESP or
// RRESP 2'b10, RDATA 0), else OKAY. WSTRB must be all ones; AWPROT and ARPROT are not
// interpreted. BVALID and RVALID hold until BREADY and RREADY.
{%- endif %}
// The samples: {= inner =}'s ports as they are{% if own_last %}, and last_i, the frame's last
// flag of a sample, read with the sample and by nothing else{% endif %}.
module {= h.module =}{= h.params =} (
{= h.ports =}
);

  wire        req, we;
  wire [{= w - 1 =}:0] addr;
  wire [31:0] wdata, rdata;
  wire [3:0]  be;
  wire        ack, err, ack_we;
{%- if wishbone %}

  assign req   = wb_cyc_i && wb_stb_i;
  assign we    = wb_we_i;
  assign addr  = wb_adr_i;
  assign wdata = wb_dat_i;
  assign be    = wb_sel_i;
  assign wb_ack_o = ack && !err;
  assign wb_err_o = ack && err;
  assign wb_dat_o = rdata;
  // Whether the access answered was a write: Wishbone's answer does not say.
  wire unused_ack_we = ack_we;
{%- else %}

  reg         bvalid_q, rvalid_q;
  reg  [1:0]  bresp_q, rresp_q;
  reg  [31:0] rdata_q;
  wire        idle   = !bvalid_q && !rvalid_q;
  wire        wr_go  = idle && s_axil_awvalid && s_axil_wvalid;
  wire        rd_go  = idle && s_axil_arvalid && !wr_go;

  assign req   = wr_go || rd_go;
  assign we    = wr_go;
  assign addr  = wr_go ? s_axil_awaddr[{= ab - 1 =}:2] : s_axil_araddr[{= ab - 1 =}:2];
  assign wdata = s_axil_wdata;
  assign be    = s_axil_wstrb;

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      bvalid_q <= 1'b0;
      rvalid_q <= 1'b0;
    end else begin
      if (ack && ack_we)
        bvalid_q <= 1'b1;
      else if (s_axil_bready)
        bvalid_q <= 1'b0;
      if (ack && !ack_we)
        rvalid_q <= 1'b1;
      else if (s_axil_rready)
        rvalid_q <= 1'b0;
    end
  end

  always @(posedge clk_i) begin
    if (ack && ack_we)
      bresp_q <= err ? 2'b10 : 2'b00;
    if (ack && !ack_we) begin
      rresp_q <= err ? 2'b10 : 2'b00;
      rdata_q <= err ? 32'd0 : rdata;
    end
  end

  assign s_axil_awready = ack && ack_we;
  assign s_axil_wready  = ack && ack_we;
  assign s_axil_bvalid  = bvalid_q;
  assign s_axil_bresp   = bresp_q;
  assign s_axil_arready = ack && !ack_we;
  assign s_axil_rvalid  = rvalid_q;
  assign s_axil_rresp   = rresp_q;
  assign s_axil_rdata   = rdata_q;
  // The byte address's offset within a word, and the protection bits: not interpreted.
  wire unused_axil = ^{s_axil_awaddr[1:0], s_axil_araddr[1:0], s_axil_awprot, s_axil_arprot};
{%- endif %}

  wire        swap, wr_en;
  wire [1:0]  wr_axis;
  wire [{= a - 1 =}:0]  wr_addr;
  wire [{= mb - 1 =}:0]  wr_data;

  {= regs =} {= regs_inst =} (
    .clk_i     (clk_i),
    .rst_ni    (rst_ni),
    .req_i     (req),
    .we_i      (we),
    .addr_i    (addr),
    .wdata_i   (wdata),
    .be_i      (be),
    .ack_o     (ack),
    .err_o     (err),
    .ack_we_o  (ack_we),
    .rdata_o   (rdata),
    .accept_i  ({= accept =}),
    .last_i    ({= last =}),
    .deliver_i ({= deliver =}),
    .wr_en_o   (wr_en),
    .wr_axis_o (wr_axis),
    .wr_addr_o (wr_addr),
    .wr_data_o (wr_data),
    .swap_o    (swap)
  );

  {= inner =}{= inner_params =} {= inner_inst =} (
{%- for p in pins %}
    {= p =}{% if !loop.last %},{% endif %}
{%- endfor %}
  );

endmodule

`default_nettype wire
