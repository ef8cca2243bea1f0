{= t.header =}
//
// Self-checking testbench of {= t.module =} with {= t.lanes =} lanes (Verilog-2005; for Icarus Verilog
// and for Verilator --binary).
//
// It reads the top's vectors, {= t.vector_file =} (or the file of +vectors=FILE), one vector per line:
//   {= t.field_list =}
// and deals them out to the lanes in file order: each beat takes the next vectors, lane 0
// first, into the lanes whose valid_i bit it sets. The first {= t.full_speed =} beats are full (every
// lane valid); then every beat has a random valid pattern (one in eight none at all).
{%- if t.handshake %}
// Backpressure on the whole beat: ready_i low one clock in four, and now and then for up to
// 63 clocks. A beat is accepted with |valid_i && ready_o and held until then; its results
// leave with |valid_o && ready_i and must hold until then.
{%- endif %}
// While the map-0 part streams, the host port writes {= t.map2_pattern =} into the back buffer
// (three clocks in four); the first map-1 vector waits until the load is complete and starts a
// beat presented with swap_i high, so the map-0 vectors before it all sit in earlier beats.
// The design is reset once mid-stream and the beats then in flight are presented again.
// Every beat must leave once, in order, with valid_o equal to its valid_i and every valid
// lane's outputs equal to its vector's, exactly LATENCY enabled clocks after it was accepted{% if t.handshake %}
// (clocks with ready_o high; at least LATENCY when backpressure came after it){% endif %}. Mismatches
// print the lane and the vector's line; the last line of a run is `N passed, M failed`
// (N counts vectors).
//
// Run from the generated directory:
//   iverilog -g2005 -Wall -Wno-timescale -s {= t.module =}_tb -o {= t.module =}_tb.vvp {= t.tb_file =} *.v
//   vvp -N {= t.module =}_tb.vvp
// or from anywhere with every file parameter below set to its path and +vectors=FILE.
`timescale 1ns / 1ps
`default_nettype none

module {= t.module =}_tb;

  localparam L          = {= t.lanes =};  // lanes
  localparam LATENCY    = {= t.latency =};  // rmapgen::stages::rmap_top::top_latency
  localparam DEPTH      = {= t.depth =};  // ring of beats accepted but not yet checked (> LATENCY + 2)
  localparam DL         = {= t.depth_bits =};  // log2(DEPTH)
  localparam VDEPTH     = {= t.vdepth =};  // ring of vectors read but not yet checked (>= L * DEPTH)
  localparam VL         = {= t.vdepth_bits =};  // log2(VDEPTH)
  localparam NFIELDS    = {= t.fields.len() =};
  localparam FULL_SPEED = {= t.full_speed =};  // full beats, back to back, before random valid patterns
  localparam RESET_AT   = {= t.reset_at =};  // accepted vectors before the mid-stream reset
  localparam TIMEOUT    = {= t.timeout =};  // clocks without an output while beats are in flight
  localparam SHOW       = 10;  // mismatches printed in full; later ones by line only
  localparam GIVE_UP    = 100;  // failures after which the run stops

  // ---------------------------------------------------------------- files
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

  // ---------------------------------------------------------------- vectors and beats
  // Vector k sits in slot k mod VDEPTH: [nout, nin) accepted, [nin, nread) read. Beat b sits
  // in slot b mod DEPTH: [bout, bin) accepted, not yet checked.
{%- for f in t.fields %}
  reg {= f.range =} v_{= f.name =} [0:VDEPTH-1];
  reg {= f.range =} s_{= f.name =};
{%- endfor %}
  integer v_line [0:VDEPTH-1];  // line in the vector file
  reg [L-1:0] b_mask [0:DEPTH-1];  // the beat's valid_i
  integer b_first [0:DEPTH-1];  // its first vector
  integer b_edge [0:DEPTH-1];  // enabled rising edges before it was accepted
{%- if t.handshake %}
  integer b_clk [0:DEPTH-1];  // clock at which it was accepted
{%- endif %}

  reg [8*512-1:0] vector_file;
  reg [8*512-1:0] vcd_file;
  integer fd, fh, r, k, lk, n, vi;
  integer nread, nin, nout;  // vectors read, accepted, checked
  integer bin, bout, nbeats;  // beats accepted, checked, formed
  integer passed, failed, errors, shown;
  integer edges;  // enabled rising edges since the stream began
  integer idle;  // clocks since the last output while beats are in flight
  integer refused;  // clocks the presented beat has waited to be accepted
  integer seed;
  integer cur_n;  // vectors in the presented beat
  reg [31:0]   rnd;
  reg [L-1:0]  cur_mask, want, mask_o;
  reg          eof, en_next, present, ok, lat_ok, stop, did_reset, swapped;
{%- if t.handshake %}
  reg          rdy_next;  // ready_i for the coming rising edge
  reg          prev_stall;  // at the last edge valid_o was not 0 and ready_i low
  reg          hold_valid;  // the beat presented at the last edge was not accepted
  reg [L+{= t.outs_bits - 1 =}:0] held_out;  // valid_o and the outputs at the last edge
  integer      stall_left;  // clocks of a long backpressure stall still to come
  integer      clocks;  // rising edges since the stream began
  integer      last_bp;  // the last clock with ready_i low
  integer      since_rst;  // clocks since reset was released
{%- endif %}
  reg [VL-1:0] vs;
  reg [DL-1:0] bs;
  // The next beat's data inputs, assembled lane by lane and then driven whole (Verilator
  // 5.006 missed a part-select write into an input read by the design's always @* logic).
{%- for f in t.in_fields %}
  reg [{= f.bits * t.lanes - 1 =}:0] nx_{= f.name =};
{%- endfor %}
{%- include "tb/map2_decls.v" %}

  // Reads the next vector into slot nread mod VDEPTH, or sets eof.
  task read_vector;
    begin
      r = $fscanf(fd, "{= t.scan_format =}\n", {= t.scan_args =});
      if (r == NFIELDS) begin
        vs = nread[VL-1:0];
{%- for f in t.fields %}
        v_{= f.name =}[vs] = s_{= f.name =};
{%- endfor %}
        v_line[vs] = nread + 1;
        nread = nread + 1;
      end else if (r <= 0 && $feof(fd) != 0) begin
        eof = 1'b1;
      end else begin
        $fatal(1, "%0s line %0d: malformed vector (%0d of %0d fields)", vector_file, nread + 1, r, NFIELDS);
      end
    end
  endtask

  // Vector slot vs into lane lk of the next beat.
  task drive_lane;
    begin
{%- for f in t.in_fields %}
      nx_{= f.name =}[lk*{= f.bits =} +: {= f.bits =}] = v_{= f.name =}[vs];
{%- endfor %}
    end
  endtask

  // Random values into lane lk of the next beat, which has no valid sample there.
  task drive_garbage;
    begin
{%- for f in t.in_fields %}
      rnd = $random(seed);
      nx_{= f.name =}[lk*{= f.bits =} +: {= f.bits =}] = rnd[{= f.bits - 1 =}:0];
{%- endfor %}
    end
  endtask

  // Checks the beat on the outputs against beat bout: its valid bits, its latency and every
  // valid lane's outputs against the lane's vector.
  task check_beat;
    begin
      bs = bout[DL-1:0];
      mask_o = b_mask[bs];
      if (valid_o !== mask_o) begin
        vi = b_first[bs];
        vs = vi[VL-1:0];
        $display("VALID beat of line %0d: valid_o %b, expected %b", v_line[vs], valid_o, mask_o);
        protocol_error("valid_o is not the beat's valid_i");
      end
{%- if t.handshake %}
      // Exact when no backpressure came after the beat; its results may wait in the queue.
      lat_ok = !((last_bp < b_clk[bs] && edges - b_edge[bs] != LATENCY) || edges - b_edge[bs] < LATENCY);
{%- else %}
      lat_ok = (edges - b_edge[bs] == LATENCY);
{%- endif %}
      if (!lat_ok) begin
        vi = b_first[bs];
        vs = vi[VL-1:0];
        $display("LATENCY beat of line %0d: output after %0d enabled clocks, expected %0d",
                 v_line[vs], edges - b_edge[bs], LATENCY);
      end
      n = 0;
      for (lk = 0; lk < L; lk = lk + 1) begin
        if (mask_o[lk]) begin
          vs = nout[VL-1:0];
          if (nout != b_first[bs] + n) $fatal(1, "testbench: beat and vector rings disagree");
          ok = lat_ok;
{%- for f in t.out_fields %}
          if ({= f.port =}[lk*{= f.bits =} +: {= f.bits =}] !== v_{= f.name =}[vs]) ok = 1'b0;
{%- endfor %}
          if (ok) begin
            passed = passed + 1;
          end else begin
            failed = failed + 1;
            if (shown < SHOW) begin
              $display("MISMATCH lane %0d line %0d: in {= t.in_format =}", lk, v_line[vs],
                       {% for f in t.fields %}{% if loop.index0 < t.fields.len() - t.out_fields.len() %}{% if loop.index0 > 0 %}, {% endif %}v_{= f.name =}[vs]{% endif %}{% endfor %});
              $display("  expected {= t.out_format =}",
                       {% for f in t.out_fields %}{% if !loop.first %}, {% endif %}v_{= f.name =}[vs]{% endfor %});
              $display("  got      {= t.out_format =}",
                       {% for f in t.out_fields %}{% if !loop.first %}, {% endif %}{= f.port =}[lk*{= f.bits =} +: {= f.bits =}]{% endfor %});
            end else begin
              $display("MISMATCH lane %0d line %0d: expected {= t.out_format =}, got {= t.out_format =}", lk, v_line[vs],
                       {% for f in t.out_fields %}{% if !loop.first %}, {% endif %}v_{= f.name =}[vs]{% endfor %},
                       {% for f in t.out_fields %}{% if !loop.first %}, {% endif %}{= f.port =}[lk*{= f.bits =} +: {= f.bits =}]{% endfor %});
            end
            shown = shown + 1;
            give_up_if_flooded;
          end
          nout = nout + 1;
          n = n + 1;
        end
      end
      bout = bout + 1;
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

  // Stops the run once GIVE_UP failures are counted; the verdict is still the last line.
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
    bin = 0;
    bout = 0;
    nbeats = 0;
    passed = 0;
    failed = 0;
    errors = 0;
    shown = 0;
    edges = 0;
    idle = 0;
    refused = 0;
    cur_n = 0;
    cur_mask = {L{1'b0}};
    eof = 1'b0;
    present = 1'b0;
    did_reset = 1'b0;
    swapped = 1'b0;
{%- if t.handshake %}
    prev_stall = 1'b0;
    hold_valid = 1'b0;
    held_out = {L+{= t.outs_bits =}{1'b0}};
    stall_left = 0;
    clocks = 0;
    last_bp = -1;
    since_rst = 0;
{%- endif %}

    // Every file this run relies on must exist: a missing $readmemh file only warns.
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

    // Reset: valid_o low throughout.
    repeat (3) begin
      @(negedge clk_i);
      if (valid_o !== {L{1'b0}}) protocol_error("valid_o not low in reset");
{%- if t.handshake %}
      if (ready_o !== 1'b0) protocol_error("ready_o not low in reset");
{%- endif %}
    end
    rst_ni = 1'b1;

    // After reset and before any input: no output.
    repeat (LATENCY + 4) begin
      @(negedge clk_i);
      if (valid_o !== {L{1'b0}}) protocol_error("valid_o before any input");
{%- if t.handshake %}
      rnd = $random(seed);
      ready_i = rnd[0];
{%- endif %}
    end

    while (!(eof && nout == nread)) begin
      @(negedge clk_i);

      // Once, mid-stream: reset with beats in flight; they are lost and presented again.
      if (!did_reset && nin >= RESET_AT) begin
        did_reset = 1'b1;
        valid_i = {L{1'b0}};
        wr_en_i = 1'b0;
        swap_i = 1'b0;
        if (swapped) $fatal(1, "the mid-stream reset must come before the swap");
        rst_ni = 1'b0;
        #1;
        if (valid_o !== {L{1'b0}}) protocol_error("valid_o did not drop with rst_ni");
{%- if t.handshake %}
        if (ready_o !== 1'b0) protocol_error("ready_o did not drop with rst_ni");
        prev_stall = 1'b0;
        hold_valid = 1'b0;
        since_rst = 0;
{%- endif %}
        repeat (2) begin
          @(negedge clk_i);
          if (valid_o !== {L{1'b0}}) protocol_error("valid_o not low in reset");
        end
        rst_ni = 1'b1;
        $display("reset mid-stream: %0d accepted, %0d in flight, presented again", nin, nin - nout);
        nin = nout;
        bin = bout;
      end

      // Flow control for the coming rising edge.
{%- if t.handshake %}
      rnd = $random(seed);
      if (stall_left > 0) begin
        rdy_next = 1'b0;
        stall_left = stall_left - 1;
      end else begin
        rdy_next = (nbeats < FULL_SPEED) || (rnd[6:0] >= 7'd32);
        if (nbeats >= FULL_SPEED && rnd[15:8] == 8'd0) stall_left = {26'd0, rnd[21:16]};
      end
      if (!rdy_next) last_bp = clocks;
      en_next = (ready_o === 1'b1);
      if (ready_o !== 1'b0 && ready_o !== 1'b1) protocol_error("ready_o is X");
      if (prev_stall && ({valid_o, {= t.outs_concat =}} !== held_out)) begin
        protocol_error("valid_o or an output changed while ready_i was low");
      end
      if (nbeats < FULL_SPEED && last_bp < 0 && since_rst > 1 && ready_o !== 1'b1) begin
        protocol_error("ready_o low without backpressure");
      end
      since_rst = since_rst + 1;
{%- else %}
      en_next = 1'b1;  // no flow control
{%- endif %}

      // The beat on the outputs leaves at the coming edge{% if t.handshake %} if ready_i{% endif %}.
      if (^valid_o === 1'bx) begin
        protocol_error("valid_o is X");
      end else if (valid_o !== {L{1'b0}}) begin
        if ({% if t.handshake %}rdy_next{% else %}1'b1{% endif %}) begin
          if (bout == bin) begin
            protocol_error("valid_o with no beat in flight");
          end else begin
            check_beat;
            idle = 0;
          end
        end
      end

      // The next beat (unless the last one waits to be accepted).
      swap_i = 1'b0;
{%- if t.handshake %}
      if (!hold_valid) begin
{%- else %}
      begin
{%- endif %}
        while (nread < nin + L && !eof) read_vector;
        rnd = $random(seed);
        if (nbeats < FULL_SPEED) want = {L{1'b1}};
        else if (rnd[2:0] == 3'd0) want = {L{1'b0}};
        else want = rnd[8 +: L];
        nbeats = nbeats + 1;
        cur_mask = {L{1'b0}};
        cur_n = 0;
        stop = 1'b0;
        for (lk = 0; lk < L; lk = lk + 1) begin
          if (want[lk] && !stop && nin + cur_n < nread) begin
            vi = nin + cur_n;
            vs = vi[VL-1:0];
            // The first map-1 vector starts a beat, once the second map is loaded.
            if (v_map[vs] == 1'b1 && !swapped && (cur_n > 0 || nwr < NWRITES)) begin
              stop = 1'b1;
            end else begin
              cur_mask[lk] = 1'b1;
              drive_lane;
              cur_n = cur_n + 1;
            end
          end
          if (!cur_mask[lk]) drive_garbage;
        end
{%- for f in t.in_fields %}
        {= f.port =} = nx_{= f.name =};
{%- endfor %}
        valid_i = cur_mask;
        present = (cur_mask != {L{1'b0}});
      end
      if (present && en_next) begin
        bs = bin[DL-1:0];
        b_mask[bs] = cur_mask;
        b_first[bs] = nin;
        b_edge[bs] = edges;
{%- if t.handshake %}
        b_clk[bs] = clocks;
{%- endif %}
        vs = nin[VL-1:0];
        if (v_map[vs] == 1'b1 && !swapped) begin
          swap_i = 1'b1;
          swapped = 1'b1;
          $display("swap with line %0d, after %0d host writes", v_line[vs], nwr);
        end
        for (k = 0; k < cur_n; k = k + 1) begin
          vi = nin + k;
          vs = vi[VL-1:0];
          if (v_map[vs] == 1'b0 && swapped) begin
            $fatal(1, "%0s line %0d: a map-0 vector after the swap", vector_file, v_line[vs]);
          end
        end
        nin = nin + cur_n;
        bin = bin + 1;
      end

      // Host writes into the back buffer, three clocks in four, never in the swap's clock.
      wr_en_i = 1'b0;
      if (nwr < NWRITES && !swap_i) begin
        rnd = $random(seed);
        if (rnd[1:0] != 2'b00) host_write;
      end
{%- if t.handshake %}
      ready_i = rdy_next;
      hold_valid = present && !en_next;
      prev_stall = (valid_o !== {L{1'b0}}) && !rdy_next;
      held_out = {valid_o, {= t.outs_concat =}};
      clocks = clocks + 1;
{%- endif %}
      if (en_next) edges = edges + 1;

      if (bout < bin) idle = idle + 1;
      if (idle > TIMEOUT) begin
        $fatal(1, "timeout: no output for %0d clocks with %0d beats in flight (checked %0d vectors)",
               TIMEOUT, bin - bout, nout);
      end
      if (present && !en_next) refused = refused + 1;
      else refused = 0;
      if (refused > TIMEOUT) begin
        $fatal(1, "timeout: a beat presented for %0d clocks is not accepted (accepted %0d)",
               TIMEOUT, nin);
      end
    end

    // Drain: with every beat out, no further output may appear.
    valid_i = {L{1'b0}};
{%- if t.handshake %}
    ready_i = 1'b1;
{%- endif %}
    repeat (LATENCY + 4) begin
      @(negedge clk_i);
      if (valid_o !== {L{1'b0}}) protocol_error("valid_o after the last beat");
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
