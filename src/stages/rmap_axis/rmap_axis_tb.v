{= t.header =}
//
// Self-checking testbench of {= t.module =}, the AXI4-Stream top (Verilog-2005; Icarus Verilog
// and Verilator --binary). It drives the wrapper's own ports and nothing inside it.
//
// It reads the top's vectors, {= t.vector_file =} (or the file of +vectors=FILE), one vector per line:
//   {= t.field_list =}
// (inputs, then expected outputs, hex) and sends each as one beat on s_axis: its fields packed
// into s_axis_tdata at their byte-aligned slots (rmapgen::stages::rmap_axis::Packing), the
// padding bits random, a random tuser{% if user_bits == 0 %} (none here: --axis-user 0){% endif %} and a random tlast (a frame ends after
// one beat in four). Every result must leave on m_axis as one beat with m_axis_tdata equal,
// bit for bit, to the expected fields at their slots with the padding 0, and with the tuser and
// tlast of its own sample. +vcd=FILE writes a VCD.
//   s_axis_tdata ({= s_bits =} bits):{% for s in s_slots %} {= s.field =} {= s.range =}{% endfor %}
//   m_axis_tdata ({= m_bits =} bits):{% for s in m_slots %} {= s.field =} {= s.range =}{% endfor %}
//
// Inputs are driven and outputs sampled on the falling edge, never right after the rising one.
// The first {= t.full_speed =} beats go back to back; then the source pauses (s_axis_tvalid low one clock
// in four, and one clock in 128 a pause of up to 15 clocks, with random values on tdata, tuser
// and tlast) and the sink applies backpressure (m_axis_tready low one clock in four, and one
// clock in 256 a stall of up to 63 clocks). AXI4-Stream's rules are checked on both sides: a
// beat offered on s_axis holds every signal until s_axis_tready takes it; a beat on m_axis must
// hold m_axis_tvalid, tdata, tuser and tlast until m_axis_tready takes it. A result leaves
// exactly LATENCY clocks with s_axis_tready high after its sample was accepted when no
// backpressure came in between, never sooner.
//
// While the map-0 part streams, the host port writes {= t.map2_pattern =} into the back buffer (three
// clocks in four; random addresses and data with wr_en_i low in the other clocks, from reset
// to the end); the first map-1 vector waits until the load is complete and is offered with
// swap_i high (a swap takes effect for the sample accepted in the same clock). The design is
// reset once mid-stream, before the swap; the samples then in flight are lost and sent again.
// Every result must leave once, in order. Mismatches print the vector's line, its inputs, the
// expected and the got; the last line of a run is `N passed, M failed`.
//
// Run from the generated directory, which holds vectors/ and the .hex files:
//   iverilog -g2005 -Wall -Wno-timescale -s {= t.module =}_tb -o {= t.module =}_tb.vvp {= t.tb_file =} *.v
//   vvp -N {= t.module =}_tb.vvp      (-N: a failing run exits 1)
// or from anywhere, with every file parameter below set to its path (iverilog
// -P{= t.module =}_tb.NAME='"path"', verilator -GNAME='"path"') and +vectors=FILE.
`timescale 1ns / 1ps
`default_nettype none

module {= t.module =}_tb;

  localparam LATENCY    = {= t.latency =};  // the latency of the top inside (rmapgen::stages::rmap_top::top_latency)
  localparam DEPTH      = {= t.depth =};  // ring of vectors read but not yet checked (> LATENCY + 2)
  localparam DL         = {= t.depth_bits =};  // log2(DEPTH)
  localparam NFIELDS    = {= t.fields.len() =};
  localparam FULL_SPEED = {= t.full_speed =};  // beats accepted back to back before pauses and backpressure
  localparam RESET_AT   = {= t.reset_at =};  // accepted beats before the mid-stream reset
  localparam TIMEOUT    = {= t.timeout =};  // clocks without an output while samples are in flight
  localparam SHOW       = 10;  // mismatches printed in full; later ones by line only
  localparam GIVE_UP    = 100;  // failures after which the run stops (a broken design floods)

  // ---------------------------------------------------------------- files
  // Every file the design or the testbench reads with $readmemh; a relative path resolves
  // against the simulator's working directory.
{%- for f in t.files %}
  parameter {= f.param =} = "{= f.default =}";
{%- endfor %}

  // ---------------------------------------------------------------- the design
{%- for p in t.inputs %}
  reg  {= p.range =} {= p.name =} = {= p.init =};
{%- endfor %}
{%- for p in t.outputs %}
  wire {= p.range =} {= p.name =};
{%- endfor %}

  {= t.module =}{= t.dut_params =} dut (
{%- for p in t.ports %}
    {= p.pin =}{% if !loop.last %},{% endif %}
{%- endfor %}
  );

  always #5 clk_i = ~clk_i;

  // ---------------------------------------------------------------- vectors
  // Slot k of each ring holds vector k mod DEPTH. Vectors [nout, nin) are in the pipeline,
  // [nin, nread) read but not yet accepted.
{%- for f in t.fields %}
  reg {= f.range =} v_{= f.name =} [0:DEPTH-1];
  reg {= f.range =} s_{= f.name =};
{%- endfor %}
{%- if user_bits > 0 %}
  reg [{= user_bits - 1 =}:0] v_user [0:DEPTH-1];  // the beat's tuser
{%- endif %}
  reg        v_last [0:DEPTH-1];  // the beat's tlast
  integer    v_line [0:DEPTH-1];  // line in the vector file
  integer    v_edge [0:DEPTH-1];  // clocks with s_axis_tready high before the beat was accepted
  integer    v_clk [0:DEPTH-1];  // clock at which it was accepted

  reg [8*512-1:0] vector_file;
  reg [8*512-1:0] vcd_file;
  integer fd, fh, r, k;
  integer nread, nin, nout;  // vectors read, accepted, checked
  integer passed, failed, errors, shown;
  integer edges;  // clocks with s_axis_tready high since the stream began
  integer idle;  // clocks since the last output while samples are in flight
  integer refused;  // clocks the offered beat has waited to be accepted
  integer seed;
  integer stall_left;  // clocks of a long backpressure stall still to come
  integer pause_left;  // clocks of a long source pause still to come
  integer clocks;  // rising edges since the stream began
  integer last_bp;  // the last clock with m_axis_tready low
  integer since_rst;  // clocks since reset was released
  reg [31:0] rnd;
  reg        eof, en_next, rdy_next, present, ok, did_reset, swapped;
  reg        prev_stall;  // at the last edge m_axis_tvalid was high and m_axis_tready low
  reg        hold_valid;  // the beat offered at the last edge was not accepted
  reg [{= s_bits - 1 =}:0] nx_tdata;  // the offered beat's s_axis_tdata, assembled, then driven whole
  reg [{= m_bits - 1 =}:0] exp_tdata;  // the expected m_axis_tdata: the result's fields, padding 0
  reg [{= held_bits - 1 =}:0] held_out;  // {m_axis_tvalid, m_axis_tdata{% if user_bits > 0 %}, m_axis_tuser{% endif %}, m_axis_tlast} at the last edge
  reg [DL-1:0] so, si;
{%- include "tb/map2_decls.v" %}

  // Reads the next vector into slot nread mod DEPTH, with the tuser and tlast of its beat, or
  // sets eof.
  task read_vector;
    begin
      r = $fscanf(fd, "{= t.scan_format =}\n", {= t.scan_args =});
      if (r == NFIELDS) begin
        si = nread[DL-1:0];
{%- for f in t.fields %}
        v_{= f.name =}[si] = s_{= f.name =};
{%- endfor %}
        rnd = $random(seed);
        v_last[si] = (rnd[1:0] == 2'b00);
{%- for (hi, lo) in user_fill %}
        rnd = $random(seed);
        v_user[si][{= hi =}:{= lo =}] = rnd[{= hi - lo =}:0];
{%- endfor %}
        v_line[si] = nread + 1;
        nread = nread + 1;
      end else if (r <= 0 && $feof(fd) != 0) begin
        eof = 1'b1;
      end else begin
        $fatal(1, "%0s line %0d: malformed vector (%0d of %0d fields)", vector_file, nread + 1, r, NFIELDS);
      end
    end
  endtask

  // Random bits into nx_tdata: the padding of a beat, or a whole word while tvalid is low.
  task random_tdata;
    begin
{%- for (hi, lo) in s_fill %}
      rnd = $random(seed);
      nx_tdata[{= hi =}:{= lo =}] = rnd[{= hi - lo =}:0];
{%- endfor %}
    end
  endtask

  // Random values on the host write port's address and data, for clocks without a write:
  // wr_en_i low must ignore them.
  task host_garbage;
    begin
{%- for (name, bits) in host_data %}
      rnd = $random(seed);
      {= name =} = rnd[{= bits - 1 =}:0];
{%- endfor %}
    end
  endtask

  // Random values on s_axis_tdata, tuser and tlast, for clocks without a beat.
  task drive_garbage;
    begin
      random_tdata;
      s_axis_tdata = nx_tdata;
{%- for (hi, lo) in user_fill %}
      rnd = $random(seed);
      s_axis_tuser[{= hi =}:{= lo =}] = rnd[{= hi - lo =}:0];
{%- endfor %}
      rnd = $random(seed);
      s_axis_tlast = rnd[0];
    end
  endtask

  // Compares the beat on m_axis with vector nout (at slot so) and counts the result.
  task check_output;
    begin
      exp_tdata = {= m_bits =}'d0;
{%- for s in m_slots %}
      exp_tdata{= s.range =} = v_{= s.field =}[so];
{%- endfor %}
      ok = (m_axis_tdata === exp_tdata){% if user_bits > 0 %} && (m_axis_tuser === v_user[so]){% endif %} && (m_axis_tlast === v_last[so]);
      // Exact when no backpressure came after the input; a result may wait in the queue.
      if ((last_bp < v_clk[so] && edges - v_edge[so] != LATENCY) || edges - v_edge[so] < LATENCY) begin
        $display("LATENCY line %0d: output after %0d clocks with s_axis_tready high, expected %0d",
                 v_line[so], edges - v_edge[so], LATENCY);
        ok = 1'b0;
      end
      if (ok) begin
        passed = passed + 1;
      end else begin
        failed = failed + 1;
        if (shown < SHOW) begin
          $display("MISMATCH line %0d: in{% for f in in_all %} {= f =}=%h{% endfor %}{% if user_bits > 0 %} tuser=%h{% endif %} tlast=%h", v_line[so],
                   {% for f in in_all %}v_{= f =}[so], {% endfor %}{% if user_bits > 0 %}v_user[so], {% endif %}v_last[so]);
          $display("  expected{% for s in m_slots %} {= s.field =}=%h{% endfor %}{% if user_bits > 0 %} tuser=%h{% endif %} tlast=%h tdata=%h",
                   {% for s in m_slots %}v_{= s.field =}[so], {% endfor %}{% if user_bits > 0 %}v_user[so], {% endif %}v_last[so], exp_tdata);
          $display("  got     {% for s in m_slots %} {= s.field =}=%h{% endfor %}{% if user_bits > 0 %} tuser=%h{% endif %} tlast=%h tdata=%h",
                   {% for s in m_slots %}m_axis_tdata{= s.range =}, {% endfor %}{% if user_bits > 0 %}m_axis_tuser, {% endif %}m_axis_tlast, m_axis_tdata);
        end else begin
          $display("MISMATCH line %0d: expected tdata=%h{% if user_bits > 0 %} tuser=%h{% endif %} tlast=%h, got tdata=%h{% if user_bits > 0 %} tuser=%h{% endif %} tlast=%h", v_line[so],
                   exp_tdata, {% if user_bits > 0 %}v_user[so], {% endif %}v_last[so], m_axis_tdata, {% if user_bits > 0 %}m_axis_tuser, {% endif %}m_axis_tlast);
        end
        shown = shown + 1;
        give_up_if_flooded;
      end
    end
  endtask

  // A protocol error: counted as a failure, printed always.
  task protocol_error;
    input [8*64-1:0] what;
    begin
      errors = errors + 1;
      $display("ERROR at %0t: %0s (vectors checked %0d, accepted %0d)", $time, what, nout, nin);
      give_up_if_flooded;
    end
  endtask

  // Stops the run once GIVE_UP failures are counted: a broken design can otherwise fail
  // every clock of a long stream, or never finish it. The verdict is still the last line.
  task give_up_if_flooded;
    begin
      if (failed + errors >= GIVE_UP) begin
        $display("stopped after %0d failures (vectors checked %0d, accepted %0d, read %0d)",
                 failed + errors, nout, nin, nread);
        $display("%0d passed, %0d failed", passed, failed + errors);
        $stop;  // exit code 1 under vvp -N and under Verilator with tb/vl_user.cpp
      end
    end
  endtask

  initial begin
    seed = {= t.seed =};
    nread = 0;
    nin = 0;
    nout = 0;
    passed = 0;
    failed = 0;
    errors = 0;
    shown = 0;
    edges = 0;
    idle = 0;
    refused = 0;
    eof = 1'b0;
    did_reset = 1'b0;
    swapped = 1'b0;
    prev_stall = 1'b0;
    hold_valid = 1'b0;
    held_out = {= held_bits =}'d0;
    nx_tdata = {= s_bits =}'d0;
    stall_left = 0;
    pause_left = 0;
    clocks = 0;
    last_bp = -1;
    since_rst = 0;

    // Every file this run relies on must exist: a missing $readmemh file only warns and
    // leaves X (Icarus) or 0 (Verilator), which a comparison may not notice.
    if (!$value$plusargs("vectors=%s", vector_file)) vector_file = "{= t.vector_file =}";
    fd = $fopen(vector_file, "r");
    if (fd == 0) $fatal(1, "cannot open %0s: run from the generated directory", vector_file);
{%- for f in t.files %}
    fh = $fopen({= f.param =}, "r");
    if (fh == 0) $fatal(1, "cannot open %0s ({= f.param =}): run from the generated directory or set it", {= f.param =});
    $fclose(fh);
{%- endfor %}
    $display("{= t.module =}_tb: {= t.summary =}, latency %0d, vectors %0s", LATENCY, vector_file);
    if ($value$plusargs("vcd=%s", vcd_file)) begin
      $dumpfile(vcd_file);
      $dumpvars(0, {= t.module =}_tb);
    end
{%- include "tb/map2_init.v" %}

    // Reset: no beat offered on m_axis, s_axis not ready.
    repeat (3) begin
      @(negedge clk_i);
      if (m_axis_tvalid !== 1'b0) protocol_error("m_axis_tvalid not low in reset");
      if (s_axis_tready !== 1'b0) protocol_error("s_axis_tready not low in reset");
    end
    rst_ni = 1'b1;

    // After reset and before any input: no output.
    repeat (LATENCY + 4) begin
      @(negedge clk_i);
      if (m_axis_tvalid !== 1'b0) protocol_error("m_axis_tvalid before any input");
      rnd = $random(seed);
      m_axis_tready = rnd[0];
      drive_garbage;
      host_garbage;
    end

    read_vector;
    while (!(eof && nout == nread)) begin
      @(negedge clk_i);

      // Once, mid-stream: reset with samples in flight. m_axis_tvalid drops at once and stays
      // low; the samples in flight are lost and sent again.
      if (!did_reset && nin >= RESET_AT) begin
        did_reset = 1'b1;
        s_axis_tvalid = 1'b0;
        wr_en_i = 1'b0;
        swap_i = 1'b0;
        if (swapped) $fatal(1, "the mid-stream reset must come before the swap");
        rst_ni = 1'b0;
        #1;
        if (m_axis_tvalid !== 1'b0) protocol_error("m_axis_tvalid did not drop with rst_ni");
        if (s_axis_tready !== 1'b0) protocol_error("s_axis_tready did not drop with rst_ni");
        prev_stall = 1'b0;
        hold_valid = 1'b0;
        since_rst = 0;
        repeat (2) begin
          @(negedge clk_i);
          if (m_axis_tvalid !== 1'b0) protocol_error("m_axis_tvalid not low in reset");
        end
        rst_ni = 1'b1;
        $display("reset mid-stream: %0d accepted, %0d in flight, sent again", nin, nin - nout);
        nin = nout;
      end

      // Backpressure for the coming rising edge: m_axis_tready low one clock in four, and one
      // clock in 256 a stall of up to 63 clocks, which fills the queue and stops the pipeline.
      rnd = $random(seed);
      if (stall_left > 0) begin
        rdy_next = 1'b0;
        stall_left = stall_left - 1;
      end else begin
        rdy_next = (nin < FULL_SPEED) || (rnd[6:0] >= 7'd32);
        if (nin >= FULL_SPEED && rnd[15:8] == 8'd0) stall_left = {26'd0, rnd[21:16]};
      end
      if (!rdy_next) last_bp = clocks;
      // A beat offered on s_axis is accepted at the coming edge iff s_axis_tready.
      en_next = (s_axis_tready === 1'b1);
      if (s_axis_tready !== 1'b0 && s_axis_tready !== 1'b1) protocol_error("s_axis_tready is X");
      // A beat not taken at the last edge stays, unchanged.
      if (prev_stall && {m_axis_tvalid, m_axis_tdata{% if user_bits > 0 %}, m_axis_tuser{% endif %}, m_axis_tlast} !== held_out) begin
        protocol_error("an m_axis signal changed while m_axis_tready was low");
      end
      // Without backpressure the pipeline never stops (after the clock that follows reset).
      if (nin < FULL_SPEED && last_bp < 0 && since_rst > 1 && s_axis_tready !== 1'b1) begin
        protocol_error("s_axis_tready low without backpressure");
      end
      since_rst = since_rst + 1;

      // The beat on m_axis leaves at the coming edge if m_axis_tready.
      if (m_axis_tvalid === 1'b1) begin
        if (rdy_next) begin
          if (nout == nin) begin
            protocol_error("m_axis_tvalid with no sample in flight");
          end else begin
            so = nout[DL-1:0];
            check_output;
            nout = nout + 1;
            idle = 0;
          end
        end
      end else if (m_axis_tvalid !== 1'b0) begin
        protocol_error("m_axis_tvalid is X");
      end

      // The next beat, unless the source pauses: one clock in four, and one clock in 128 a
      // pause of up to 15 clocks. A beat offered at the last edge and not taken stays.
      if (nin == nread && !eof) read_vector;
      rnd = $random(seed);
      if (pause_left > 0) begin
        present = 1'b0;
        pause_left = pause_left - 1;
      end else begin
        present = (nin < nread) && ((nin < FULL_SPEED) || (rnd[6:0] >= 7'd32));
        if (nin >= FULL_SPEED && rnd[14:8] == 7'd0) pause_left = {28'd0, rnd[19:16]};
      end
      // The first map-1 vector waits for the second map to be loaded.
      swap_i = 1'b0;
      if (present && !swapped && v_map[nin[DL-1:0]] == 1'b1 && nwr < NWRITES) present = 1'b0;
      if (hold_valid) present = 1'b1;
      if (present) begin
        si = nin[DL-1:0];
        // A new beat's padding is random; a beat offered again keeps every bit.
        if (!hold_valid) begin
          random_tdata;
{%- for s in s_slots %}
          nx_tdata{= s.range =} = v_{= s.field =}[si];
{%- endfor %}
        end
        s_axis_tdata = nx_tdata;
{%- if user_bits > 0 %}
        s_axis_tuser = v_user[si];
{%- endif %}
        s_axis_tlast = v_last[si];
        s_axis_tvalid = 1'b1;
        if (en_next) begin
          v_edge[si] = edges;
          v_clk[si] = clocks;
          if (v_map[si] == 1'b1 && !swapped) begin
            swap_i = 1'b1;
            swapped = 1'b1;
            $display("swap with line %0d, after %0d host writes", v_line[si], nwr);
          end
          if (v_map[si] == 1'b0 && swapped) begin
            $fatal(1, "%0s line %0d: a map-0 vector after the swap", vector_file, v_line[si]);
          end
          nin = nin + 1;
        end
      end else begin
        s_axis_tvalid = 1'b0;
        drive_garbage;
      end

      // Host writes into the back buffer, three clocks in four, never in the swap's clock;
      // random values on the write port in the other clocks.
      wr_en_i = 1'b0;
      if (nwr < NWRITES && !swap_i) begin
        rnd = $random(seed);
        if (rnd[1:0] != 2'b00) host_write;
      end
      if (!wr_en_i) host_garbage;
      m_axis_tready = rdy_next;
      hold_valid = present && !en_next;
      prev_stall = (m_axis_tvalid === 1'b1) && !rdy_next;
      held_out = {m_axis_tvalid, m_axis_tdata{% if user_bits > 0 %}, m_axis_tuser{% endif %}, m_axis_tlast};
      clocks = clocks + 1;
      if (en_next) edges = edges + 1;

      if (nout < nin) idle = idle + 1;
      if (idle > TIMEOUT) begin
        $fatal(1, "timeout: no output for %0d clocks with %0d samples in flight (checked %0d)",
               TIMEOUT, nin - nout, nout);
      end
      // A beat offered but never accepted: the design stopped taking input.
      if (present && !en_next) refused = refused + 1;
      else refused = 0;
      if (refused > TIMEOUT) begin
        $fatal(1, "timeout: a beat offered for %0d clocks is not accepted (accepted %0d)",
               TIMEOUT, nin);
      end
    end

    // Drain: with every sample out, no further output may appear.
    s_axis_tvalid = 1'b0;
    m_axis_tready = 1'b1;
    repeat (LATENCY + 4) begin
      @(negedge clk_i);
      if (m_axis_tvalid !== 1'b0) protocol_error("m_axis_tvalid after the last sample");
    end
    if (!swapped) protocol_error("no map-1 vector: the buffer swap was not tested");

    $fclose(fd);
    $display("%0d passed, %0d failed", passed, failed + errors);
    if (failed + errors != 0 || passed == 0) begin
      $stop;  // exit code 1 under vvp -N and under Verilator with tb/vl_user.cpp
    end
    $finish;
  end

endmodule

`default_nettype wire
