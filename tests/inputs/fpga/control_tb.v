// robovec tests: rv_control's program counter and its fetch two cycles ahead (rv_lib.v). A
// control memory whose word k is k, registered twice as rv_pe registers it (the block RAM's
// output, then `ctrl`), must give word pc during every clock the program runs, for a start
// after idle clocks and for one in the clock after `done`. Macros: CW, CYCLES, N (the number
// of checks: 3 runs of CYCLES + 1 clocks), VEC (unused).
`timescale 1ns/1ps
module control_tb;
  reg clk = 0, rst = 0, start = 0;
  wire run, done;
  wire [`CW-1:0] pc, fetch;
  rv_control #(.CW(`CW), .CYCLES(`CYCLES)) ctl (.clk(clk), .rst(rst), .start(start), .run(run), .done(done), .pc(pc), .fetch(fetch));
  // the block RAM (word k = k; nothing beyond the program's cycles) and the PE's register
  reg [`CW-1:0] rom_q = 0, ctrl = 0;
  always @(posedge clk) begin
    rom_q <= (fetch <= `CYCLES) ? fetch : 0;
    ctrl <= rom_q;
  end
  integer checks = 0, bad = 0, k, runs;
  always #5 clk = ~clk;
  // during each running clock (sampled at the negative edge): word pc is in `ctrl`
  always @(negedge clk) if (run) begin
    checks = checks + 1;
    if (ctrl !== pc) begin
      bad = bad + 1;
      $display("mismatch: pc %0d, control word %0d", pc, ctrl);
    end
  end
  initial begin
    @(negedge clk); @(negedge clk); @(negedge clk);
    for (runs = 0; runs < 3; runs = runs + 1) begin
      start = 1; @(negedge clk); start = 0;
      while (!done) @(negedge clk);
      // the second run starts in the clock after `done`, the third after three idle clocks
      if (runs == 1) for (k = 0; k < 3; k = k + 1) @(negedge clk);
    end
    $display("checked %0d vectors, %0d mismatches", checks, bad);
    $finish;
  end
endmodule
