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

// PE memory: binary32 words, two write ports and two read ports per cycle (the seed's
// double-pumped M10K), write-first: reads of a clock see the writes of the same clock.
// `host_*` writes a word while the design is idle (to change inputs between runs).
module rv_pe_mem #(
    parameter integer AW = 11,
    parameter integer DEPTH = 1,
    parameter FILE = ""
) (
    input  wire          clk,
    input  wire          we0,
    input  wire [AW-1:0] wa0,
    input  wire [31:0]   wd0,
    input  wire          we1,
    input  wire [AW-1:0] wa1,
    input  wire [31:0]   wd1,
    input  wire [AW-1:0] ra,
    input  wire [AW-1:0] rb,
    output reg  [31:0]   qa,
    output reg  [31:0]   qb
);
  reg [31:0] mem [0:DEPTH-1];
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

