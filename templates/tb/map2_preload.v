

    // Load the second map{% if t.table_entries > 0 %} and table{% endif %} into buffer 1; no output may appear meanwhile.
    wr_buf_i = 1'b1;
    while (nwr < NWRITES) begin
      @(negedge clk_i);
      if (valid_o !== 1'b0) protocol_error("valid_o during the map load");
      rnd = $random(seed);
      en_i = rnd[0];
      host_write;
    end
    @(negedge clk_i);
    wr_en_i = 1'b0;
