// robovec codegen<fpga>: the fixed-point units (issue 49).
//
// A design whose values are all fixed point (`fix<w,f>`, w <= 32: what `precision<target=mcu>`
// chooses) has fixed-point PEs: its words are 32-bit two's complement integers k of values
// k * 2^-f, every value with its own f (robovec's `ir/src/format.rs`, "integer op"). An op is
// computed exactly on the operands' integers, aligned by a constant shift, then rounded once to
// the result's format: what `-eval` computes and the C back end writes as `int64_t` arithmetic.
//
//   fix_add_sub #(.LATENCY(L)) u (.clk, .a, .b, .sub, .sh, .y);   ADD PE
//   fix_mul     #(.LATENCY(L)) u (.clk, .a, .b, .sh, .y);         MULTI PE
//
// The exact result is registered before its rounding (`fix_stages`), then a delay line.
// `sh` is the op's shift word (the PE's shift memory `peS_fix`, one word per cycle, registered
// with the operands):
//   [0,6)  align: the bits the aligned operand is shifted left (the two operands' fractions
//          differ by it);
//   bit 6  1: align b, 0: align a (ADD PE only; a MULTI PE's product is not aligned);
//   [7,14) s, two's complement: the bits the exact result's fraction exceeds the result's.
//          s > 0 rounds to nearest, ties toward +inf: (K + 2^(s-1)) >>> s; s <= 0 shifts K left
//          by -s.
// The exact intermediate K fits 64 bits (robovec's `INTEGER_BITS` bound, with the range proof
// of every value: the result fits its w <= 32 bits, so y is K's low 32 bits after rounding).
// The multiplier is a 32 x 32 signed product: DSP blocks on the device (Cyclone V: two
// variable-precision blocks for 36 x 36; ECP5: four MULT18X18D). y is the result of the
// operands presented LATENCY rising edges earlier: the exact result in the first clock (the
// product in two: its partial products, then their sum), its rounding in the next, then a delay
// line (measured on the ECP5-85F with nextpnr, the double pendulum's 2 + 2 design: 58 MHz with
// the rounding in the product's clock, 77 MHz split, 88 MHz with the partial products
// registered; docs/fpga.md).

// Rounding of the exact result K by s bits (see above).
module fix_round (
    input  wire signed [63:0] k,
    input  wire        [6:0]  s,
    output wire        [31:0] y
);
  wire        neg = s[6];
  wire [5:0]  right = s[5:0];
  wire [5:0]  left = 6'd0 - s[5:0];
  wire signed [63:0] half = (right == 6'd0) ? 64'sd0 : (64'sd1 <<< (right - 6'd1));
  wire signed [63:0] r = neg ? (k <<< left) : ((k + half) >>> right);
  assign y = r[31:0];
endmodule

// The stages after the exact result K: with LATENCY >= 1, K and the shift are registered
// before the rounding (the arithmetic and the rounding in separate clocks), then LATENCY - 1
// delay stages; with LATENCY = 0, combinational.
module fix_stages #(parameter integer LATENCY = 1) (
    input  wire               clk,
    input  wire signed [63:0] k,
    input  wire        [6:0]  s,
    output wire        [31:0] y
);
  wire [31:0] r;
  generate
    if (LATENCY == 0) begin : g_comb
      fix_round rnd (.k(k), .s(s), .y(r));
      assign y = r;
    end else begin : g_split
      reg signed [63:0] k_q;
      reg        [6:0]  s_q;
      initial begin
        k_q = 0;
        s_q = 0;
      end
      always @(posedge clk) begin
        k_q <= k;
        s_q <= s;
      end
      fix_round rnd (.k(k_q), .s(s_q), .y(r));
      fp_delay #(.LATENCY(LATENCY - 1)) line (.clk(clk), .d(r), .q(y));
    end
  endgenerate
endmodule

// The ADD PE's unit: y = round(align(a) +- align(b)), LATENCY clocks after the operands.
module fix_add_sub #(parameter integer LATENCY = 1) (
    input  wire        clk,
    input  wire [31:0] a,
    input  wire [31:0] b,
    input  wire        sub,
    input  wire [13:0] sh,
    output wire [31:0] y
);
  wire signed [63:0] ea = {{32{a[31]}}, a};
  wire signed [63:0] eb = {{32{b[31]}}, b};
  wire [5:0] al = sh[5:0];
  wire signed [63:0] xa = sh[6] ? ea : (ea <<< al);
  wire signed [63:0] xb = sh[6] ? (eb <<< al) : eb;
  wire signed [63:0] k = sub ? (xa - xb) : (xa + xb);
  fix_stages #(.LATENCY(LATENCY)) st (.clk(clk), .k(k), .s(sh[13:7]), .y(y));
endmodule

// The MULTI PE's unit: y = round(a * b), LATENCY clocks after the operands. With LATENCY >= 2
// the product is split in four 16 x 16 partial products (one MULT18X18D each on the ECP5, one
// 18 x 19 half block each on the Cyclone V), registered, then summed in the next clock.
module fix_mul #(parameter integer LATENCY = 2) (
    input  wire        clk,
    input  wire [31:0] a,
    input  wire [31:0] b,
    input  wire [13:0] sh,
    output wire [31:0] y
);
  generate
    if (LATENCY >= 2) begin : g_split
      // a = ah·2^16 + al with ah signed and al unsigned (b likewise)
      wire signed [15:0] ah = a[31:16];
      wire signed [15:0] bh = b[31:16];
      wire signed [16:0] al = {1'b0, a[15:0]};
      wire signed [16:0] bl = {1'b0, b[15:0]};
      reg  signed [31:0] hh;
      reg  signed [32:0] hl, lh;
      reg  signed [33:0] ll;
      reg         [6:0]  s1;
      initial begin
        hh = 0;
        hl = 0;
        lh = 0;
        ll = 0;
        s1 = 0;
      end
      always @(posedge clk) begin
        hh <= ah * bh;
        hl <= ah * bl;
        lh <= al * bh;
        ll <= al * bl;
        s1 <= sh[13:7];
      end
      wire signed [63:0] k = ({{32{hh[31]}}, hh} <<< 32) + ({{31{hl[32]}}, hl} <<< 16)
                             + ({{31{lh[32]}}, lh} <<< 16) + {{30{ll[33]}}, ll};
      fix_stages #(.LATENCY(LATENCY - 1)) st (.clk(clk), .k(k), .s(s1), .y(y));
    end else begin : g_whole
      wire signed [31:0] sa = a;
      wire signed [31:0] sb = b;
      wire signed [63:0] k = sa * sb;
      fix_stages #(.LATENCY(LATENCY)) st (.clk(clk), .k(k), .s(sh[13:7]), .y(y));
    end
  endgenerate
endmodule
