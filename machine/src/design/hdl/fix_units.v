// robovec codegen<fpga>: the fixed-point units (issue 49).
//
// A design whose values are all fixed point (`fix<w,f>`, w <= 32: what `precision<target=mcu>`
// chooses, `word=` for narrower words) has fixed-point PEs: its words are DW-bit two's complement
// integers k of values k * 2^-f (DW = the widest w of the function, the design's `word_bits`),
// every value with its own f (robovec's `ir/src/format.rs`, "integer op"). An op is
// computed exactly on the operands' integers, aligned by a constant shift, then rounded once to
// the result's format: what `-eval` computes and the C back end writes as `int64_t` arithmetic.
//
//   fix_add_sub #(.LATENCY(L), .DW(w), .KW(k), .RMAX(r), .AMAX(a), .SMIN(s0), .SMAX(s1)) u (.clk, .a, .b, .sub, .sh, .y);
//   fix_mul     #(.LATENCY(L), .DW(w), .KW(k), .SMIN(s0), .SMAX(s1)) u (.clk, .a, .b, .sh, .y);
//   fix_mac     #(.LATENCY(L), .DW(w), .KW(k), .AMAX(a), .SMIN(s0), .SMAX(s1)) u (.clk, .a, .b, .c, .mac, .negp, .sub, .sh, .y);
//
// The exact result is registered before its rounding (`fix_stages`), then a delay line when
// L > 1 (robovec's PEs take L = 1: the rounding goes straight into the PE's result register).
// AMAX, SMIN and SMAX bound the alignments and rounding shifts of the PE's program (the
// generator's `shift_ranges`): the shifters cover only those.
// `sh` is the op's shift word (the PE's shift memory `peS_fix`, one word per cycle, registered
// with the operands; the ADD unit takes it in its floored form, see fix_add_sub):
//   [0,6)  align: the bits the aligned operand is shifted left (the two operands' fractions
//          differ by it);
//   bit 6  1: align b, 0: align a (ADD PE only; a MULTI PE's product is not aligned);
//   [7,14) s, two's complement: the bits the exact result's fraction exceeds the result's.
//          s > 0 rounds to nearest, ties toward +inf: (K + 2^(s-1)) >>> s; s <= 0 shifts K left
//          by -s.
// The exact intermediate K is computed in KW <= 64 bits: the generator gives each PE the
// width its program needs (robovec's `machine/src/design/build.rs`, `intermediate_bits`: the
// floored sum's DW + max(D, 1) bits, the product's 2 DW + 1, and the rounding constant's
// s + 2), within robovec's `INTEGER_BITS` bound; with the range proof of every value the result
// fits its w <= DW bits, so y is the low DW bits after rounding. The multiplier is a DW x DW
// signed product: one 27 x 27 variable-precision DSP block on the Cyclone V for DW <= 27, two
// beyond; on the ECP5 one MULT18X18D for DW <= 18, four beyond. y is the result of the
// operands presented LATENCY rising edges earlier: the exact result in the first clock (a split
// product in two: its partial products, then their sum), its rounding in the next, then a delay
// line of LATENCY - 1 clocks (measured on the ECP5-85F with nextpnr, the double pendulum's 2 + 2 design: 58 MHz with
// the rounding in the product's clock, 77 MHz split, 88 MHz with the partial products
// registered; docs/fpga.md).

// Rounding of the exact result K by s bits (see above), for the shifts SMIN <= s <= SMAX of the
// PE's program (the generator's `shift_ranges`; the defaults take any 7-bit s). One shifter:
//   t = K >>> (s - 1)  (K << (1 - s) when s <= 0),  y = (t + [s >= 1]) >>> 1,
// which is (K + 2^(s-1)) >>> s for s >= 1 (floor((floor(K / 2^(s-1)) + 1) / 2) is
// floor((K + 2^(s-1)) / 2^s)) and K << -s for s <= 0. Only the low DW + 1 bits of t are used,
// so the shifter keeps DW + 1 outputs, and it shifts by s - SMIN (ceil(log2(SMAX - SMIN + 1))
// levels) after a constant shift: a MULTI PE whose products round by 24 to 26 bits has a
// two-level shifter, where any s took two 6-level ones and a KW-bit adder.
module fix_round #(parameter integer DW = 32, parameter integer KW = 64,
                   parameter integer SMIN = -64, parameter integer SMAX = 63) (
    input  wire signed [KW-1:0] k,
    input  wire        [6:0]    s,
    output wire        [DW-1:0] y
);
  // room on the right for the left shifts (s <= 0), the constant part of the shift, its span
  localparam integer P = (SMIN <= 0) ? 1 - SMIN : 0;
  localparam integer C0 = SMIN - 1 + P;
  localparam integer SPAN = SMAX - SMIN;
  localparam integer BB = (SPAN <= 0) ? 1 : $clog2(SPAN + 1);
  localparam integer EW = KW + P;
  wire signed [EW-1:0] ke = k;  // sign-extends
  wire signed [EW-1:0] e = (ke <<< P) >>> C0;
  wire        [6:0]    smin7 = SMIN;
  wire        [6:0]    b7 = s - smin7;
  wire        [BB-1:0] b = (SPAN <= 0) ? {BB{1'b0}} : b7[BB-1:0];
  wire signed [EW-1:0] t = e >>> b;
  wire                 up = ~s[6] & (s != 7'd0);
  wire        [DW:0]   r = t[DW:0] + {{DW{1'b0}}, up};
  assign y = r[DW:1];
endmodule

// The stages after the exact result K: with LATENCY >= 1, K and the shift are registered
// before the rounding (the arithmetic and the rounding in separate clocks), then LATENCY - 1
// delay stages; with LATENCY = 0, combinational.
module fix_stages #(parameter integer LATENCY = 1, parameter integer DW = 32, parameter integer KW = 64,
                    parameter integer SMIN = -64, parameter integer SMAX = 63) (
    input  wire                 clk,
    input  wire signed [KW-1:0] k,
    input  wire        [6:0]    s,
    output wire        [DW-1:0] y
);
  wire [DW-1:0] r;
  generate
    if (LATENCY == 0) begin : g_comb
      fix_round #(.DW(DW), .KW(KW), .SMIN(SMIN), .SMAX(SMAX)) rnd (.k(k), .s(s), .y(r));
      assign y = r;
    end else begin : g_split
      reg signed [KW-1:0] k_q;
      reg        [6:0]    s_q;
      initial begin
        k_q = 0;
        s_q = 0;
      end
      always @(posedge clk) begin
        k_q <= k;
        s_q <= s;
      end
      fix_round #(.DW(DW), .KW(KW), .SMIN(SMIN), .SMAX(SMAX)) rnd (.k(k_q), .s(s_q), .y(r));
      fp_delay #(.LATENCY(LATENCY - 1), .W(DW)) line (.clk(clk), .d(r), .q(y));
    end
  endgenerate
endmodule

// The ADD PE's unit: y = round(a +- b) of two operands on different grids, LATENCY clocks after
// the operands, in robovec's floored form (`FloorShifts`, machine/src/design/build.rs): a is the
// finer operand, floored by r bits (an arithmetic right shift: floor(a / 2^r)), b the coarser,
// shifted left by l bits, and their sum rounded by D bits (fix_round; a left shift when D <= 0).
// With r = min(A, S - 1) of the op's alignment A and rounding S (0 when S <= 0), l = A - r and
// D = S - r this is exactly the rounding by S of the aligned sum (the floor drops only bits below
// the grid the rounding keeps), and D is 0 or 1 for nearly every op: the adder and the rounding
// are about the result's width, not the aligned sum's DW + A + 2 bits. The generator reads the
// finer operand at port A (it swaps the reads of an op whose b is the finer) and sh[6] says
// which side `sub` negates: 1 the coarser (a - b with b coarser), 0 the finer. A negated finer
// operand is floored as floor(-a / 2^r) = floor(~a / 2^r) + [a mod 2^r = 0] (the carry in).
// `sh` (20 bits, rv_pe's shift word): [0,6) l, bit 6 which side is negated, [7,14) D in two's
// complement, [14,20) r. RMAX, AMAX (the largest l), SMIN and SMAX (D's range) bound the
// program's shifts (the generator's `floored_shift_ranges`): the shifters cover only those. KW
// is the sum's width, DW + max(DMAX, 1) (the generator's `intermediate_bits`): the sum is exact
// modulo 2^KW in the bits the rounding keeps.
module fix_add_sub #(parameter integer LATENCY = 1, parameter integer DW = 32, parameter integer KW = 64,
                     parameter integer RMAX = 62, parameter integer AMAX = 63, parameter integer SMIN = -64,
                     parameter integer SMAX = 63) (
    input  wire          clk,
    input  wire [DW-1:0] a,
    input  wire [DW-1:0] b,
    input  wire          sub,
    input  wire [19:0]   sh,
    output wire [DW-1:0] y
);
  localparam integer RB = (RMAX <= 0) ? 1 : $clog2(RMAX + 1);
  localparam integer LB = (AMAX <= 0) ? 1 : $clog2(AMAX + 1);
  wire [RB-1:0] r = (RMAX <= 0) ? {RB{1'b0}} : sh[14 +: RB];
  wire [LB-1:0] l = (AMAX <= 0) ? {LB{1'b0}} : sh[LB-1:0];
  wire nega = sub & ~sh[6];
  wire negb = sub & sh[6];
  // signed assignments to wider wires sign-extend
  wire signed [KW-1:0] ea = $signed(a);
  wire signed [KW-1:0] eb = $signed(b);
  wire signed [KW-1:0] na = ea ^ {KW{nega}};
  wire signed [KW-1:0] xa = na >>> r;
  wire signed [KW-1:0] xb = (eb <<< l) ^ {KW{negb}};
  // the carry in: -b = ~b + 1; floor(-a / 2^r) = floor(~a / 2^r) + 1 when a's low r bits are 0
  wire zlow;
  generate
    if (RMAX <= 0) begin : g_no_floor
      assign zlow = 1'b1;
    end else begin : g_floor
      wire [DW-1:0] low = ~({DW{1'b1}} << r);
      assign zlow = ~|(a & low);
    end
  endgenerate
  wire cin = nega ? zlow : negb;
  wire signed [KW-1:0] k = xa + xb + {{(KW-1){1'b0}}, cin};
  fix_stages #(.LATENCY(LATENCY), .DW(DW), .KW(KW), .SMIN(SMIN), .SMAX(SMAX)) st (.clk(clk), .k(k), .s(sh[13:7]), .y(y));
endmodule

// A signed DW x DW product as four registered partial products of the (DW - 16)-bit signed high
// and 16-bit unsigned low halves (one MULT18X18D each on the ECP5, one 18 x 19 half block each
// on the Cyclone V), summed after the register and sign-extended to KW bits: p is the product
// of the a, b of the previous clock. fix_mul's and fix_mac's product for words wider than ONE.
module fix_split_product #(parameter integer DW = 32, parameter integer KW = 64) (
    input  wire                 clk,
    input  wire        [DW-1:0] a,
    input  wire        [DW-1:0] b,
    output wire signed [KW-1:0] p
);
  localparam integer HW = DW - 16;
  // a = ah·2^16 + al with ah signed and al unsigned (b likewise)
  wire signed [HW-1:0] ah = a[DW-1:16];
  wire signed [HW-1:0] bh = b[DW-1:16];
  wire signed [16:0]   al = {1'b0, a[15:0]};
  wire signed [16:0]   bl = {1'b0, b[15:0]};
  reg  signed [2*HW-1:0] hh;
  reg  signed [HW+16:0]  hl, lh;
  reg  signed [33:0]     ll;
  initial begin
    hh = 0;
    hl = 0;
    lh = 0;
    ll = 0;
  end
  always @(posedge clk) begin
    hh <= ah * bh;
    hl <= ah * bl;
    lh <= al * bh;
    ll <= al * bl;
  end
  // signed assignments to wider wires sign-extend
  wire signed [KW-1:0] ehh = hh;
  wire signed [KW-1:0] ehl = hl;
  wire signed [KW-1:0] elh = lh;
  wire signed [KW-1:0] ell = ll;
  assign p = (ehh <<< 32) + (ehl <<< 16) + (elh <<< 16) + ell;
endmodule

// The MULTI PE's unit: y = round(a * b), LATENCY clocks after the operands. For DW <= ONE (the
// family's widest one-multiplier word: 27 on the Cyclone V, a block in 27 x 27 mode; 18 on the
// ECP5, a MULT18X18D) the product is one DSP multiplier, registered, then rounded in the next
// clock. For wider words with LATENCY >= 2 the product is split in four partial products of
// the (DW - 16)-bit signed high and 16-bit unsigned low halves (one MULT18X18D each on the
// ECP5, one 18 x 19 half block each on the Cyclone V), registered, then summed in the next
// clock.
module fix_mul #(parameter integer LATENCY = 2, parameter integer DW = 32, parameter integer KW = 64,
                 parameter integer SMIN = -64, parameter integer SMAX = 63, parameter integer ONE = 27) (
    input  wire          clk,
    input  wire [DW-1:0] a,
    input  wire [DW-1:0] b,
    input  wire [13:0]   sh,
    output wire [DW-1:0] y
);
  generate
    if (LATENCY >= 2 && DW > ONE) begin : g_split
      wire signed [KW-1:0] k;
      reg         [6:0]    s1;
      initial s1 = 0;
      always @(posedge clk) s1 <= sh[13:7];
      fix_split_product #(.DW(DW), .KW(KW)) pp (.clk(clk), .a(a), .b(b), .p(k));
      fix_stages #(.LATENCY(LATENCY - 1), .DW(DW), .KW(KW), .SMIN(SMIN), .SMAX(SMAX)) st (.clk(clk), .k(k), .s(s1), .y(y));
    end else begin : g_whole
      wire signed [DW-1:0]   sa = a;
      wire signed [DW-1:0]   sb = b;
      wire signed [2*DW-1:0] p = sa * sb;
      wire signed [KW-1:0]   k = p;  // sign-extends (or keeps the low KW >= the product's bits)
      fix_stages #(.LATENCY(LATENCY), .DW(DW), .KW(KW), .SMIN(SMIN), .SMAX(SMAX)) st (.clk(clk), .k(k), .s(sh[13:7]), .y(y));
    end
  endgenerate
endmodule

// The MULTI PE's unit with fused multiply-adds (`rv_pe`'s MAC = 1; robovec's `contract` after
// `precision<target=mcu>`): y = round(+-(a * b << lp) +- (c << lc)), LATENCY clocks after the
// operands, exactly robovec's `FixShifts::apply_fused` (ir/src/machine.rs): with sh[6] (align b)
// the addend c is shifted left by sh[5:0], else the product; `negp` negates the product (fnma),
// `sub` the addend (fms); then the rounding by sh[13:7] of fix_round. With `mac` low the op is a
// plain product (the addend, its alignment and the negations gated off): y = round(a * b).
// LATENCY >= 2: the product is registered first (a DSP multiplier's output register, or the four
// partial products of a word wider than ONE, as fix_mul), with the addend and the op's fields;
// the aligned sum is registered in the next clock (fix_stages), then rounded, then a delay line
// of LATENCY - 2 clocks. KW covers the aligned sum (robovec's `mac_intermediate_bits`, at most
// 64 bits: every exact intermediate of an integer op is at most 62 bits).
module fix_mac #(parameter integer LATENCY = 2, parameter integer DW = 32, parameter integer KW = 64,
                 parameter integer AMAX = 63, parameter integer SMIN = -64, parameter integer SMAX = 63,
                 parameter integer ONE = 27) (
    input  wire          clk,
    input  wire [DW-1:0] a,
    input  wire [DW-1:0] b,
    input  wire [DW-1:0] c,
    input  wire          mac,
    input  wire          negp,
    input  wire          sub,
    input  wire [13:0]   sh,
    output wire [DW-1:0] y
);
  localparam integer AB = (AMAX <= 0) ? 1 : $clog2(AMAX + 1);
  localparam integer LS = (LATENCY >= 2) ? LATENCY - 1 : LATENCY;  // the stages after the product
  wire signed [KW-1:0] p;   // the product, sign-extended to KW bits
  wire signed [DW-1:0] c1;  // the addend and the op's fields, of the product's clock
  wire                 mac1, negp1, sub1;
  wire        [13:0]   sh1;
  generate
    if (LATENCY >= 2) begin : g_reg
      reg signed [DW-1:0] c_q;
      reg                 mac_q, negp_q, sub_q;
      reg        [13:0]   sh_q;
      initial begin
        c_q = 0;
        {mac_q, negp_q, sub_q} = 0;
        sh_q = 0;
      end
      always @(posedge clk) begin
        c_q <= c;
        mac_q <= mac;
        negp_q <= negp;
        sub_q <= sub;
        sh_q <= sh;
      end
      assign c1 = c_q;
      assign {mac1, negp1, sub1} = {mac_q, negp_q, sub_q};
      assign sh1 = sh_q;
      if (DW > ONE) begin : g_split
        fix_split_product #(.DW(DW), .KW(KW)) pp (.clk(clk), .a(a), .b(b), .p(p));
      end else begin : g_whole
        wire signed [DW-1:0]   sa = a;
        wire signed [DW-1:0]   sb = b;
        reg  signed [2*DW-1:0] p_q;
        initial p_q = 0;
        always @(posedge clk) p_q <= sa * sb;
        assign p = p_q;  // sign-extends
      end
    end else begin : g_comb
      wire signed [DW-1:0]   sa = a;
      wire signed [DW-1:0]   sb = b;
      wire signed [2*DW-1:0] pc = sa * sb;
      assign p = pc;
      assign c1 = c;
      assign {mac1, negp1, sub1} = {mac, negp, sub};
      assign sh1 = sh;
    end
  endgenerate
  wire side = sh1[6];
  wire [AB-1:0] al = (AMAX <= 0 || !mac1) ? {AB{1'b0}} : sh1[AB-1:0];
  wire signed [KW-1:0] ce = c1;  // sign-extends
  wire signed [KW-1:0] ec = mac1 ? ce : {KW{1'b0}};
  wire np = mac1 & negp1;
  wire nc = mac1 & sub1;
  // one shifter for both sides (as fix_add_sub): the aligned term first, each negated as
  // x ^ {KW{n}} plus n
  wire signed [KW-1:0] sp = side ? ec : p;
  wire signed [KW-1:0] sq = side ? p : ec;
  wire signed [KW-1:0] xs = sp <<< al;
  wire ns = side ? nc : np;
  wire nq = side ? np : nc;
  wire signed [KW-1:0] k = (xs ^ {KW{ns}}) + (sq ^ {KW{nq}}) + {{(KW-2){1'b0}}, ns & nq, ns ^ nq};
  fix_stages #(.LATENCY(LS), .DW(DW), .KW(KW), .SMIN(SMIN), .SMAX(SMAX)) st (.clk(clk), .k(k), .s(sh1[13:7]), .y(y));
endmodule
