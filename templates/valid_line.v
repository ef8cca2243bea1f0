
  // ---------------------------------------------------------------- valid bits
  // One per clock of latency: bit k is the valid bit of the sample k + 1 clocks in.
  reg [LATENCY-1:0] valid_q;

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      valid_q <= {LATENCY{1'b0}};
    end else if (en_i) begin
{%- if latency == 1 %}
      valid_q <= valid_i;
{%- else %}
      valid_q <= {valid_q[LATENCY-2:0], valid_i};
{%- endif %}
    end
  end

  assign valid_o = valid_q[LATENCY-1];
