// robovec codegen<fpga>: the memories of the generated design, as inferred RAMs/ROMs initialised
// from `$readmemh` images (Quartus infers M10K blocks; the initial contents go into the bitstream
// through the same files or their MIF twins). Replaced by black boxes in the resource estimate
// (synth_stubs.v), where memories are counted as M10K blocks from their sizes.

// Synchronous-read ROM initialised from a `$readmemh` image (an M10K in ROM mode).
module rv_rom #(
    parameter integer WIDTH = 8,
    parameter integer DEPTH = 1,
    parameter integer AW = 1,
    parameter FILE = ""
) (
    input  wire             clk,
    input  wire [AW-1:0]    addr,
    output reg  [WIDTH-1:0] q
);
  reg [WIDTH-1:0] mem [0:DEPTH-1];
  initial begin
    if (FILE != "") $readmemh(FILE, mem);
    q = 0;
  end
  always @(posedge clk) q <= (addr < DEPTH) ? mem[addr] : {WIDTH{1'b0}};
endmodule

// PE memory: DW-bit words (binary32, or the fixed-point PEs' word), two write ports and two read ports per cycle (the seed's
// double-pumped M10K), write-first: reads of a clock see the writes of the same clock.
// `host_*` writes a word while the design is idle (to change inputs between runs).
module rv_pe_mem #(
    parameter integer AW = 11,
    parameter integer DEPTH = 1,
    parameter integer DW = 32,
    parameter FILE = ""
) (
    input  wire          clk,
    input  wire          we0,
    input  wire [AW-1:0] wa0,
    input  wire [DW-1:0] wd0,
    input  wire          we1,
    input  wire [AW-1:0] wa1,
    input  wire [DW-1:0] wd1,
    input  wire [AW-1:0] ra,
    input  wire [AW-1:0] rb,
    output reg  [DW-1:0] qa,
    output reg  [DW-1:0] qb
);
  reg [DW-1:0] mem [0:DEPTH-1];
  initial begin
    if (FILE != "") $readmemh(FILE, mem);
    qa = 0;
    qb = 0;
  end
  always @(posedge clk) begin
    if (we0) mem[wa0] <= wd0;
    if (we1) mem[wa1] <= wd1;
    qa <= (we1 && wa1 == ra) ? wd1 : (we0 && wa0 == ra) ? wd0 : mem[ra];
    qb <= (we1 && wa1 == rb) ? wd1 : (we0 && wa0 == rb) ? wd0 : mem[rb];
  end
endmodule

// The same PE memory for block RAMs without two write ports at twice the clock (the ECP5's
// DP16KD: `rv_pe` with LVT = 1, targets of family `ecp5`), with the same behaviour cycle for cycle.
// Built from one-write one-read banks with a live-value table (LaForest & Steffan, FPGA 2010):
// bank `m<w><r>` holds what write port w stored, for read port r (so each bank is a simple
// dual-port RAM that any FPGA's block RAM implements: M10K, ECP5 DP16KD, or LUT RAM when
// shallow), and `lvt` says which write port stored each word last. The banks are read into
// registers; the bank choice and the same-clock bypass are decided from registered copies,
// after them. Initial contents (inputs, constants): both write ports' banks, live value port 0.
module rv_pe_mem_lvt #(
    parameter integer AW = 11,
    parameter integer DEPTH = 1,
    parameter integer DW = 32,
    parameter FILE = ""
) (
    input  wire          clk,
    input  wire          we0,
    input  wire [AW-1:0] wa0,
    input  wire [DW-1:0] wd0,
    input  wire          we1,
    input  wire [AW-1:0] wa1,
    input  wire [DW-1:0] wd1,
    input  wire [AW-1:0] ra,
    input  wire [AW-1:0] rb,
    output wire [DW-1:0] qa,
    output wire [DW-1:0] qb
);
  reg [DW-1:0] m0a [0:DEPTH-1];
  reg [DW-1:0] m0b [0:DEPTH-1];
  reg [DW-1:0] m1a [0:DEPTH-1];
  reg [DW-1:0] m1b [0:DEPTH-1];
  reg        lvt [0:DEPTH-1];
  reg [DW-1:0] r0a, r0b, r1a, r1b, fwd_a, fwd_b;
  reg        live_a, live_b, by_a, by_b;
  integer i;
  initial begin
    if (FILE != "") begin
      $readmemh(FILE, m0a);
      $readmemh(FILE, m0b);
      $readmemh(FILE, m1a);
      $readmemh(FILE, m1b);
    end
    for (i = 0; i < DEPTH; i = i + 1) lvt[i] = 1'b0;
    {r0a, r0b, r1a, r1b, fwd_a, fwd_b} = 0;
    {live_a, live_b, by_a, by_b} = 0;
  end
  always @(posedge clk) begin
    if (we0) begin
      m0a[wa0] <= wd0;
      m0b[wa0] <= wd0;
    end
    if (we1) begin
      m1a[wa1] <= wd1;
      m1b[wa1] <= wd1;
    end
    r0a <= m0a[ra];
    r1a <= m1a[ra];
    r0b <= m0b[rb];
    r1b <= m1b[rb];
  end
  always @(posedge clk) begin
    if (we0) lvt[wa0] <= 1'b0;
    if (we1) lvt[wa1] <= 1'b1;
    live_a <= lvt[ra];
    live_b <= lvt[rb];
    by_a <= (we1 && wa1 == ra) || (we0 && wa0 == ra);
    by_b <= (we1 && wa1 == rb) || (we0 && wa0 == rb);
    fwd_a <= (we1 && wa1 == ra) ? wd1 : wd0;
    fwd_b <= (we1 && wa1 == rb) ? wd1 : wd0;
  end
  assign qa = by_a ? fwd_a : live_a ? r1a : r0a;
  assign qb = by_b ? fwd_b : live_b ? r1b : r0b;
endmodule

// Output memory: captures the arriving results of the PE's outputs (one write port) and gives
// them to the host after `done` through a registered read port (the word at `ra` one clock
// later): a simple dual-port block RAM (M10K, EBR) instead of registers and a read multiplexer
// in logic (issue 49). Initial contents: outputs that are inputs or constants.
module rv_out_mem #(
    parameter integer DW = 32,
    parameter integer DEPTH = 1,
    parameter integer AW = 1,
    parameter FILE = ""
) (
    input  wire          clk,
    input  wire          we,
    input  wire [AW-1:0] wa,
    input  wire [DW-1:0] wd,
    input  wire [AW-1:0] ra,
    output reg  [DW-1:0] q
);
  reg [DW-1:0] mem [0:DEPTH-1];
  initial begin
    if (FILE != "") $readmemh(FILE, mem);
    q = 0;
  end
  always @(posedge clk) begin
    if (we) mem[wa] <= wd;
    q <= mem[ra];
  end
endmodule
