{= t.header =}
//
// Self-checking testbench of {= t.module =} (Verilog-2005; Icarus Verilog and Verilator --binary).
{%- block description %}{% endblock %}
//
// Run from the generated directory, which holds vectors/ and the .hex files:
//   iverilog -g2005 -Wall -Wno-timescale -s {= t.module =}_tb -o {= t.module =}_tb.vvp {= t.tb_file =} *.v
//   vvp -N {= t.module =}_tb.vvp      (-N: a failing run exits 1)
{%- if !t.files.is_empty() %}
// or from anywhere, with every file parameter below set to its path (iverilog
// -P{= t.module =}_tb.NAME='"path"', verilator -GNAME='"path"') and +vectors=FILE.
{%- endif %}
// It reads {= t.vector_file =} (or the file of +vectors=FILE), one vector per line:
//   {= t.field_list =}
// (inputs, then expected outputs, hex); +vcd=FILE writes a VCD. Inputs are driven and outputs sampled on the falling
// edge, never right after the rising one. The first {= t.full_speed =} vectors are accepted back to back;
{%- if t.has_en %}
// then random bubbles (valid_i low) and stalls (en_i low) follow.
{%- else if t.handshake %}
// then random bubbles (valid_i low) and backpressure (ready_i low one clock in four, and now
// and then for up to 63 clocks) follow. A sample is accepted with valid_i && ready_o and held
// until then; a result leaves with valid_o && ready_i and must hold until then.
{%- else %}
// then random bubbles (valid_i low) follow ({= t.module =} has no clock enable).
{%- endif %}
// The design is reset once mid-stream and the samples then in flight are presented again.
// Every output must leave once, in order, {% if t.has_en %}when valid_o && en_i{% else if t.handshake %}when valid_o && ready_i{% else %}when valid_o{% endif %} at a rising edge, exactly
// LATENCY enabled clocks after its input{% if t.handshake %} (clocks with ready_o high; at least LATENCY when
// backpressure came after its input){% endif %}. Mismatches print the vector's line; the last line
// of a run is `N passed, M failed`.
`timescale 1ns / 1ps
`default_nettype none

module {= t.module =}_tb;

  localparam LATENCY    = {= t.latency =};  // the latency of {= t.module =} (its register plan, src/stages)
  localparam DEPTH      = {= t.depth =};  // ring of vectors read but not yet checked (> LATENCY + 2)
  localparam DL         = {= t.depth_bits =};  // log2(DEPTH)
  localparam NFIELDS    = {= t.fields.len() =};
  localparam FULL_SPEED = {= t.full_speed =};  // vectors accepted back to back before bubbles{% if t.has_en %} and stalls{% endif %}
  localparam RESET_AT   = {= t.reset_at =};  // accepted vectors before the mid-stream reset
  localparam TIMEOUT    = {= t.timeout =};  // clocks without an output while samples are in flight
  localparam SHOW       = 10;  // mismatches printed in full; later ones by line only
  localparam GIVE_UP    = 100;  // failures after which the run stops (a broken design floods)

{%- if !t.files.is_empty() %}

  // ---------------------------------------------------------------- files
  // Every file the design or the testbench reads with $readmemh; a relative path resolves
  // against the simulator's working directory.
{%- for f in t.files %}
  parameter {= f.param =} = "{= f.default =}";
{%- endfor %}
{%- endif %}

  // ---------------------------------------------------------------- the design
{%- for p in t.inputs %}
  reg  {= p.range =} {= p.name =} = {= p.init =};
{%- endfor %}
{%- for p in t.outputs %}
  wire {= p.range =} {= p.name =};
{%- endfor %}
{%- if !t.rom.is_empty() %}
{= t.rom =}
{%- endif %}

  {= t.module =}{= t.dut_params =} dut (
{%- for p in t.ports %}
    {= p.pin =}{% if !loop.last %},{% endif %}
{%- endfor %}
  );

  always #5 clk_i = ~clk_i;

  // ---------------------------------------------------------------- vectors
  // Slot k of each ring holds a field of vector k mod DEPTH. Vectors [nout, nin) are in the
  // pipeline, [nin, nread) read but not yet accepted.
{%- for f in t.fields %}
  reg {= f.range =} v_{= f.name =} [0:DEPTH-1];
  reg {= f.range =} s_{= f.name =};
{%- endfor %}
  integer v_line [0:DEPTH-1];  // line in the vector file
  integer v_edge [0:DEPTH-1];  // enabled rising edges before the vector was accepted

  reg [8*512-1:0] vector_file;
  reg [8*512-1:0] vcd_file;
  integer fd, {% if !t.files.is_empty() %}fh, {% endif %}r;
  integer nread, nin, nout;  // vectors read, accepted, checked
  integer passed, failed, errors, shown;
  integer edges;  // enabled rising edges since the stream began
  integer idle;  // clocks since the last output while samples are in flight
  integer refused;  // clocks the presented sample has waited to be accepted
  integer seed;{% if !t.map2_params.is_empty() %}
  integer k;{% endif %}
  reg [31:0]   rnd;
  reg          eof, en_next, present, ok, did_reset;
{%- if t.handshake %}
  reg          rdy_next;  // ready_i for the coming rising edge
  reg          prev_stall;  // at the last edge valid_o was high and ready_i low
  reg          hold_valid;  // the sample presented at the last edge was not accepted
  reg [{= t.outs_bits - 1 =}:0] held_out;  // the outputs at the last edge
  integer      stall_left;  // clocks of a long backpressure stall still to come
  integer      clocks;  // rising edges since the stream began
  integer      last_bp;  // the last clock with ready_i low
  integer      since_rst;  // clocks since reset was released
  integer      v_clk [0:DEPTH-1];  // clock at which the vector was accepted
{%- endif %}
  reg [DL-1:0] so, si;
{%- block decls %}{% endblock %}

  // Reads the next vector into slot nread mod DEPTH, or sets eof.
  task read_vector;
    begin
      r = $fscanf(fd, "{= t.scan_format =}\n", {= t.scan_args =});
      if (r == NFIELDS) begin
        si = nread[DL-1:0];
{%- for f in t.fields %}
        v_{= f.name =}[si] = s_{= f.name =};
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

  // Random values on the data inputs, for clocks without a valid sample.
  task drive_garbage;
    begin
{%- for f in t.in_fields %}
      rnd = $random(seed);
      {= f.port =} = rnd[{= f.bits - 1 =}:0];
{%- endfor %}
    end
  endtask

  // Compares the outputs with vector nout (at slot so) and counts the result.
  task check_output;
    begin
      ok = 1'b1;
{%- for f in t.out_fields %}
      if ({= f.port =} !== v_{= f.name =}[so]) ok = 1'b0;
{%- endfor %}
{%- if t.handshake %}
      // Exact when no backpressure came after the input; a result may wait in the queue.
      if ((last_bp < v_clk[so] && edges - v_edge[so] != LATENCY) || edges - v_edge[so] < LATENCY) begin
{%- else %}
      if (edges - v_edge[so] != LATENCY) begin
{%- endif %}
        $display("LATENCY line %0d: output after %0d enabled clocks, expected %0d",
                 v_line[so], edges - v_edge[so], LATENCY);
        ok = 1'b0;
      end
      if (ok) begin
        passed = passed + 1;
      end else begin
        failed = failed + 1;
        if (shown < SHOW) begin
          $display("MISMATCH line %0d: in {= t.in_format =}", v_line[so],
                   {= t.in_args =});
          $display("  expected {= t.out_format =}", {= t.exp_args =});
          $display("  got      {= t.out_format =}", {= t.got_args =});
        end else begin
          $display("MISMATCH line %0d: expected {= t.out_format =}, got {= t.out_format =}", v_line[so],
                   {= t.exp_args =}, {= t.got_args =});
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
{%- if t.handshake %}
    prev_stall = 1'b0;
    hold_valid = 1'b0;
    held_out = {= t.outs_bits =}'d0;
    stall_left = 0;
    clocks = 0;
    last_bp = -1;
    since_rst = 0;
{%- endif %}

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
    // +vcd=FILE: every signal of the testbench and the design into a VCD (make wave); a
    // Verilated testbench dumps only when built with --trace. No plusarg, no dump.
    if ($value$plusargs("vcd=%s", vcd_file)) begin
      $dumpfile(vcd_file);
      $dumpvars(0, {= t.module =}_tb);
    end
{%- block init %}{% endblock %}

    // Reset: valid_o low throughout.
    repeat (3) begin
      @(negedge clk_i);
      if (valid_o !== 1'b0) protocol_error("valid_o not low in reset");
{%- if t.handshake %}
      if (ready_o !== 1'b0) protocol_error("ready_o not low in reset");
{%- endif %}
    end
    rst_ni = 1'b1;
{%- block preload %}{% endblock %}

    // After reset and before any input: no output.
    repeat (LATENCY + 4) begin
      @(negedge clk_i);
      if (valid_o !== 1'b0) protocol_error("valid_o before any input");
{%- if t.has_en %}
      rnd = $random(seed);
      en_i = rnd[0];
{%- endif %}
{%- if t.handshake %}
      rnd = $random(seed);
      ready_i = rnd[0];
{%- endif %}
    end

    read_vector;
    while (!(eof && nout == nread)) begin
      @(negedge clk_i);

      // Once, mid-stream: reset with samples in flight. valid_o drops at once and stays low;
      // the samples in flight are lost and presented again.
      if (!did_reset && nin >= RESET_AT) begin
        did_reset = 1'b1;
        valid_i = 1'b0;
{%- block reset_quiet %}{% endblock %}
        rst_ni = 1'b0;
        #1;
        if (valid_o !== 1'b0) protocol_error("valid_o did not drop with rst_ni");
{%- if t.handshake %}
        if (ready_o !== 1'b0) protocol_error("ready_o did not drop with rst_ni");
        prev_stall = 1'b0;
        hold_valid = 1'b0;
        since_rst = 0;
{%- endif %}
        repeat (2) begin
          @(negedge clk_i);
          if (valid_o !== 1'b0) protocol_error("valid_o not low in reset");
        end
        rst_ni = 1'b1;
        $display("reset mid-stream: %0d accepted, %0d in flight, presented again", nin, nin - nout);
        nin = nout;
      end

      // Flow control for the coming rising edge.
{%- if t.has_en %}
      rnd = $random(seed);
      en_next = (nin < FULL_SPEED) || (rnd[6:0] >= 7'd32);  // a stall one clock in four
{%- else if t.handshake %}
      // Backpressure: ready_i low one clock in four, and one clock in 256 a stall of up to
      // 63 clocks, which fills the queue and stops the pipeline.
      rnd = $random(seed);
      if (stall_left > 0) begin
        rdy_next = 1'b0;
        stall_left = stall_left - 1;
      end else begin
        rdy_next = (nin < FULL_SPEED) || (rnd[6:0] >= 7'd32);
        if (nin >= FULL_SPEED && rnd[15:8] == 8'd0) stall_left = {26'd0, rnd[21:16]};
      end
      if (!rdy_next) last_bp = clocks;
      // The design's own enable: the pipeline advances at the coming edge iff ready_o.
      en_next = (ready_o === 1'b1);
      if (ready_o !== 1'b0 && ready_o !== 1'b1) protocol_error("ready_o is X");
      // A result not taken at the last edge stays, unchanged.
      if (prev_stall && (valid_o !== 1'b1 || {= t.outs_concat =} !== held_out)) begin
        protocol_error("valid_o or an output changed while ready_i was low");
      end
      // Without backpressure the pipeline never stops (after the clock that follows reset).
      if (nin < FULL_SPEED && last_bp < 0 && since_rst > 1 && ready_o !== 1'b1) begin
        protocol_error("ready_o low without backpressure");
      end
      since_rst = since_rst + 1;
{%- else %}
      en_next = 1'b1;  // {= t.module =} has no clock enable
{%- endif %}

      // The output leaves at the coming edge if valid_o && {% if t.handshake %}ready_i{% else %}en_i{% endif %}.
      if (valid_o === 1'b1) begin
        if ({% if t.handshake %}rdy_next{% else %}en_next{% endif %}) begin
          if (nout == nin) begin
            protocol_error("valid_o with no sample in flight");
          end else begin
            so = nout[DL-1:0];
            check_output;
            nout = nout + 1;
            idle = 0;
          end
        end
      end else if (valid_o !== 1'b0) begin
        protocol_error("valid_o is X");
      end

      // The next input, unless this clock is a bubble.
      if (nin == nread && !eof) read_vector;
      rnd = $random(seed);
      present = (nin < nread) && ((nin < FULL_SPEED) || (rnd[6:0] >= 7'd32));  // a bubble one clock in four
{%- if t.handshake %}
      if (hold_valid) present = 1'b1;  // a presented sample stays until it is accepted
{%- endif %}
{%- block hold %}{% endblock %}
      if (present) begin
        si = nin[DL-1:0];
{%- for f in t.in_fields %}
        {= f.port =} = v_{= f.name =}[si];
{%- endfor %}
        valid_i = 1'b1;
        if (en_next) begin
          v_edge[si] = edges;
{%- if t.handshake %}
          v_clk[si] = clocks;
{%- endif %}
{%- block accept %}{% endblock %}
          nin = nin + 1;
        end
      end else begin
        valid_i = 1'b0;
        drive_garbage;
      end
{%- block host %}{% endblock %}
{%- if t.has_en %}
      en_i = en_next;
{%- endif %}
{%- if t.handshake %}
      ready_i = rdy_next;
      hold_valid = present && !en_next;
      prev_stall = (valid_o === 1'b1) && !rdy_next;
      held_out = {= t.outs_concat =};
      clocks = clocks + 1;
{%- endif %}
      if (en_next) edges = edges + 1;

      if (nout < nin) idle = idle + 1;
      if (idle > TIMEOUT) begin
        $fatal(1, "timeout: no output for %0d clocks with %0d samples in flight (checked %0d)",
               TIMEOUT, nin - nout, nout);
      end
      // A sample presented but never accepted: the design stopped taking input.
      if (present && !en_next) refused = refused + 1;
      else refused = 0;
      if (refused > TIMEOUT) begin
        $fatal(1, "timeout: a sample presented for %0d clocks is not accepted (accepted %0d)",
               TIMEOUT, nin);
      end
    end

    // Drain: with every sample out, no further output may appear.
    valid_i = 1'b0;
{%- if t.has_en %}
    en_i = 1'b1;
{%- endif %}
{%- if t.handshake %}
    ready_i = 1'b1;
{%- endif %}
    repeat (LATENCY + 4) begin
      @(negedge clk_i);
      if (valid_o !== 1'b0) protocol_error("valid_o after the last sample");
    end
{%- block finish %}{% endblock %}

    $fclose(fd);
    $display("%0d passed, %0d failed", passed, failed + errors);
    if (failed + errors != 0 || passed == 0) begin
      $stop;  // exit code 1 under vvp -N and under Verilator with tb/vl_user.cpp
    end
    $finish;
  end

endmodule

`default_nettype wire
