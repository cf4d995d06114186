// Black boxes for the resource estimate (codegen<fpga>'s Yosys run): the floating-point units
// are counted from the target's per-unit costs (seed Table 1.4; the fixed-point units from the
// target's `fix_pe`) and the memories as M10K blocks
// from their sizes, so Yosys counts only the logic around them (crossbar, control, buffers,
// output memories, address decoding).
(* blackbox *)
module fp_add_sub #(parameter integer LATENCY = 10) (
    input wire clk, input wire [31:0] a, input wire [31:0] b, input wire sub, output wire [31:0] y);
endmodule

(* blackbox *)
module fp_mul #(parameter integer LATENCY = 5) (
    input wire clk, input wire [31:0] a, input wire [31:0] b, output wire [31:0] y);
endmodule

(* blackbox *)
module fix_add_sub #(parameter integer LATENCY = 2, parameter integer DW = 32, parameter integer KW = 64,
                     parameter integer RMAX = 62, parameter integer AMAX = 63, parameter integer SMIN = -64,
                     parameter integer SMAX = 63) (
    input wire clk, input wire [DW-1:0] a, input wire [DW-1:0] b, input wire sub, input wire [19:0] sh,
    output wire [DW-1:0] y);
endmodule

(* blackbox *)
module fix_mul #(parameter integer LATENCY = 3, parameter integer DW = 32, parameter integer KW = 64,
                 parameter integer SMIN = -64, parameter integer SMAX = 63, parameter integer ONE = 27) (
    input wire clk, input wire [DW-1:0] a, input wire [DW-1:0] b, input wire [13:0] sh, output wire [DW-1:0] y);
endmodule

(* blackbox *)
module fix_mac #(parameter integer LATENCY = 2, parameter integer DW = 32, parameter integer KW = 64,
                 parameter integer AMAX = 63, parameter integer SMIN = -64, parameter integer SMAX = 63,
                 parameter integer ONE = 27) (
    input wire clk, input wire [DW-1:0] a, input wire [DW-1:0] b, input wire [DW-1:0] c, input wire mac,
    input wire negp, input wire sub, input wire [13:0] sh, output wire [DW-1:0] y);
endmodule

(* blackbox *)
module rv_rom #(parameter integer WIDTH = 8, parameter integer DEPTH = 1, parameter integer AW = 1,
                parameter FILE = "") (
    input wire clk, input wire [AW-1:0] addr, output wire [WIDTH-1:0] q);
endmodule

(* blackbox *)
module rv_pe_mem #(parameter integer AW = 11, parameter integer DEPTH = 1, parameter integer DW = 32,
    parameter FILE = "") (
    input wire clk, input wire we0, input wire [AW-1:0] wa0, input wire [DW-1:0] wd0,
    input wire we1, input wire [AW-1:0] wa1, input wire [DW-1:0] wd1,
    input wire [AW-1:0] ra, input wire [AW-1:0] rb, output wire [DW-1:0] qa, output wire [DW-1:0] qb);
endmodule
module rv_pe_mem_lvt #(parameter integer AW = 11, parameter integer DEPTH = 1, parameter integer DW = 32,
    parameter FILE = "") (
    input wire clk, input wire we0, input wire [AW-1:0] wa0, input wire [DW-1:0] wd0,
    input wire we1, input wire [AW-1:0] wa1, input wire [DW-1:0] wd1,
    input wire [AW-1:0] ra, input wire [AW-1:0] rb, output wire [DW-1:0] qa, output wire [DW-1:0] qb);
endmodule
(* blackbox *)
module rv_out_mem #(parameter integer DW = 32, parameter integer DEPTH = 1, parameter integer AW = 1,
    parameter FILE = "") (
    input wire clk, input wire we, input wire [AW-1:0] wa, input wire [DW-1:0] wd,
    input wire [AW-1:0] ra, output wire [DW-1:0] q);
endmodule
