// Checks fix_units.v (issue 49) against vectors computed by robovec's model of the fixed-point
// PEs (tests/fpga.rs: exact integer ops, then FixShifts::round). Each line of VEC holds 33 hex
// digits: [131:128] op (0 add, 1 sub, 2 mul), [127:96] a, [95:64] b, [63:32] the shift word
// (14 bits used), [31:0] the expected y. One vector at a time: the operands are held for the
// unit's latency, then y is compared. `DW (default 32) is the units' word: the operands are the
// fields' low DW bits and the low DW bits of y are compared; `KWA` and `KWM` (default 64) are the
// ADD and MULTI units' intermediate bits; `RMAX` (default 62) the ADD unit's largest floor, `AMAX`
// (default 63) its largest lift (robovec's FloorShifts: the tb converts each ADD vector's shift
// word to that form and reads the finer operand at a, as the generator's control word does) and
// `SMINA7`, `SMAXA7` (ADD), `SMINM7`, `SMAXM7` (MULTI) their rounding shifts' bounds as 7-bit two's
// complement (default -64 ... 63: any shift), as the generator sizes a PE's shifters; `ONE`
// (default 27, the Cyclone V's; 18 the ECP5's) the widest word whose product is one multiplier.
`timescale 1ns/1ps
`ifndef DW
`define DW 32
`endif
`ifndef KWA
`define KWA 64
`endif
`ifndef KWM
`define KWM 64
`endif
`ifndef AMAX
`define AMAX 63
`endif
`ifndef RMAX
`define RMAX 62
`endif
`ifndef ONE
`define ONE 27
`endif
`ifndef SMINA7
`define SMINA7 64
`endif
`ifndef SMAXA7
`define SMAXA7 63
`endif
`ifndef SMINM7
`define SMINM7 64
`endif
`ifndef SMAXM7
`define SMAXM7 63
`endif
module fix_check_tb;
  localparam integer LADD = 2, LMUL = 3;
  // the 7-bit two's complement bounds as integers
  localparam integer SMINA = (`SMINA7 >= 64) ? `SMINA7 - 128 : `SMINA7;
  localparam integer SMAXA = (`SMAXA7 >= 64) ? `SMAXA7 - 128 : `SMAXA7;
  localparam integer SMINM = (`SMINM7 >= 64) ? `SMINM7 - 128 : `SMINM7;
  localparam integer SMAXM = (`SMAXM7 >= 64) ? `SMAXM7 - 128 : `SMAXM7;
  reg clk = 0;
  always #5 clk = ~clk;
  reg [131:0] vec [0:`N-1];
  reg [`DW-1:0] a = 0, b = 0, fa = 0, cb = 0;
  reg [13:0] sh = 0;
  reg [19:0] fsh = 0;
  reg sub = 0;
  wire [`DW-1:0] y_add, y_mul;
  fix_add_sub #(.LATENCY(LADD), .DW(`DW), .KW(`KWA), .RMAX(`RMAX), .AMAX(`AMAX), .SMIN(SMINA), .SMAX(SMAXA)) u_add (.clk(clk), .a(fa), .b(cb), .sub(sub), .sh(fsh), .y(y_add));
  fix_mul #(.LATENCY(LMUL), .DW(`DW), .KW(`KWM), .SMIN(SMINM), .SMAX(SMAXM), .ONE(`ONE)) u_mul (.clk(clk), .a(a), .b(b), .sh(sh), .y(y_mul));
  integer i, k, bad, al, s, r;
  reg [3:0] op;
  reg [`DW-1:0] want, got;
  initial begin
    $readmemh(`VEC, vec);
    bad = 0;
    for (i = 0; i < `N; i = i + 1) begin
      @(negedge clk);
      op = vec[i][131:128];
      a = vec[i][96+`DW-1:96];
      b = vec[i][64+`DW-1:64];
      sh = vec[i][45:32];
      sub = (op == 4'd1);
      // the floored form: r = min(A, S - 1) for S >= 1, else 0; the finer operand at a
      al = sh[5:0];
      s = (sh[13] ? -128 : 0) + sh[13:7];
      r = (s >= 1) ? ((al < s - 1) ? al : s - 1) : 0;
      fsh = {r[5:0], s[6:0] - r[6:0], sh[6], al[5:0] - r[5:0]};
      fa = sh[6] ? a : b;
      cb = sh[6] ? b : a;
      want = vec[i][`DW-1:0];
      for (k = 0; k < ((op == 4'd2) ? LMUL : LADD); k = k + 1) @(negedge clk);
      got = (op == 4'd2) ? y_mul : y_add;
      if (got !== want) begin
        bad = bad + 1;
        if (bad <= 10) $display("mismatch %0d: op %0d a %h b %h sh %h: got %h, want %h", i, op, a, b, sh, got, want);
      end
    end
    $display("checked %0d vectors, %0d mismatches", `N, bad);
    $finish;
  end
endmodule
