// robovec codegen<fpga>: the floating-point unit boundary (issue 12).
//
// Two modules, `fp_add_sub` and `fp_mul`, are the only places where the generated design does
// floating-point arithmetic. Their ports are the boundary a user re-binds to Intel's
// floating-point IP in Quartus (ALTERA_FP_FUNCTIONS / "Floating Point Functions" Intel FPGA IP,
// add/sub and multiply, single precision): keep the module names and ports, replace the body.
//
//   fp_add_sub #(.LATENCY(L)) u (.clk, .a, .b, .sub, .y);   y = sub ? a - b : a + b
//   fp_mul     #(.LATENCY(L)) u (.clk, .a, .b, .y);         y = a * b
//
// a, b, y are IEEE 754 binary32 words; y is the result of the operands presented LATENCY rising
// clock edges earlier (LATENCY = 0: combinational). The models here are a combinational,
// bit-exact binary32 core followed by a LATENCY-deep delay line (a synthesis tool can retime
// it; Intel's IP is a true pipeline of the same depth).
//
// Arithmetic (what robovec's interpreter computes with Rust `f32`, i.e. x86-64 SSE `addss`,
// `subss`, `mulss`, and C `float`):
//   * round to nearest, ties to even; subnormal operands and results handled as IEEE 754 does
//     (gradual underflow, no flush to zero);
//   * overflow rounds to infinity; inf - inf and 0 * inf give the x86 default NaN 0xFFC00000;
//   * a NaN operand propagates quieted (bit 22 set), the first operand's when both are NaN
//     (the x86 SSE rule);
//   * an exact zero sum of operands of opposite signs is +0; (-0) + (-0) = -0.
// Intel's IP flushes subnormal operands and results to zero by default ("denormal support" is an
// option of the Floating Point Functions IP); with that default, outputs that pass through a
// subnormal differ from robovec's binary32 evaluation. Robotran models rarely reach |x| < 2^-126.
// NaN can arise in robovec's f32 evaluation from finite inputs (an overflow to infinity followed
// by inf - inf or 0 * inf), so the models reproduce x86's NaN bits; Intel's IP returns its own
// quiet NaN, which is a different bit pattern but still a NaN.

// Combinational binary32 add/subtract, round to nearest even.
module fp_add_sub_comb (
    input  wire [31:0] a,
    input  wire [31:0] b,
    input  wire        sub,
    output reg  [31:0] y
);
  reg         sa, sb, sl, same;
  reg  [7:0]  ea, eb;
  reg  [22:0] fa, fb;
  reg         a_nan, b_nan, a_inf, b_inf;
  reg  [8:0]  xa, xb, xl, xs, d;
  reg  [23:0] ma, mb, ml, ms;
  reg  [50:0] bg, sml, s, shifted;
  reg         sticky, g, st;
  integer     p, i, sh, ef, il;
  reg  [50:0] m;
  reg  [31:0] bits;
  always @* begin
    sa = a[31]; ea = a[30:23]; fa = a[22:0];
    sb = b[31] ^ sub; eb = b[30:23]; fb = b[22:0];
    a_nan = (ea == 8'hff) && (fa != 0);
    b_nan = (eb == 8'hff) && (fb != 0);
    a_inf = (ea == 8'hff) && (fa == 0);
    b_inf = (eb == 8'hff) && (fb == 0);
    y = 32'h0;
    // defaults so that every reg is assigned on every path (no latches)
    sl = 0; same = 0; xa = 0; xb = 0; xl = 0; xs = 0; d = 0; ma = 0; mb = 0; ml = 0; ms = 0;
    bg = 0; sml = 0; s = 0; shifted = 0; sticky = 0; g = 0; st = 0; p = 0; i = 0; sh = 0; ef = 0; il = 0;
    m = 0; bits = 0;
    if (a_nan) y = a | 32'h0040_0000;
    else if (b_nan) y = b | 32'h0040_0000;
    else if (a_inf && b_inf && (sa != sb)) y = 32'hffc0_0000;
    else if (a_inf) y = a;
    else if (b_inf) y = {sb, 8'hff, 23'h0};
    else begin
      xa = (ea == 0) ? 9'd1 : {1'b0, ea};
      xb = (eb == 0) ? 9'd1 : {1'b0, eb};
      ma = {ea != 0, fa};
      mb = {eb != 0, fb};
      same = (sa == sb);
      if ({xa, ma} >= {xb, mb}) begin
        sl = sa; xl = xa; ml = ma; xs = xb; ms = mb;
      end else begin
        sl = sb; xl = xb; ml = mb; xs = xa; ms = ma;
      end
      d = xl - xs;
      // significands at bits [49:26]; the smaller one shifted right, lost bits kept as sticky
      bg = {1'b0, ml, 26'b0};
      sml = {1'b0, ms, 26'b0};
      if (d >= 51) begin
        shifted = 0;
        sticky = (ms != 0);
      end else begin
        shifted = sml >> d;
        sticky = ((shifted << d) != sml);
      end
      shifted[0] = shifted[0] | sticky;
      s = same ? bg + shifted : bg - shifted;
      if (s == 0) begin
        y = {same ? sl : 1'b0, 31'h0};
      end else begin
        // value = s * 2^(xl - 127 - 49); p = position of the leading one
        p = 0;
        for (i = 0; i < 51; i = i + 1) if (s[i]) p = i;
        // shift so that the leading one lands on bit 23 (normal) or the 2^-149 unit (subnormal)
        il = xl;
        sh = (p - 23 > 27 - il) ? p - 23 : 27 - il;
        ef = il + sh - 26;  // biased exponent of the unrounded result (1 for subnormals)
        if (sh > 0) begin
          m = s >> sh;
          g = s[sh-1];
          st = ((s << (51 - sh + 1)) != 0);
        end else begin
          m = s << (-sh);
          g = 0;
          st = 0;
        end
        if (g && (st || m[0])) m = m + 1;
        bits = ((ef - 1) << 23) + m[31:0];
        if (ef - 1 >= 255 || bits >= 32'h7f80_0000) y = {sl, 8'hff, 23'h0};
        else y = {sl, bits[30:0]};
      end
    end
  end
endmodule

// Combinational binary32 multiply, round to nearest even.
module fp_mul_comb (
    input  wire [31:0] a,
    input  wire [31:0] b,
    output reg  [31:0] y
);
  reg         sa, sb, sy;
  reg  [7:0]  ea, eb;
  reg  [22:0] fa, fb;
  reg         a_nan, b_nan, a_inf, b_inf, a_zero, b_zero;
  reg  [23:0] ma, mb;
  reg  [47:0] prod;
  reg  [63:0] m, pw;
  reg         g, st;
  integer     xa, xb, p, i, sh, ef;
  reg  [63:0] bits;
  always @* begin
    sa = a[31]; ea = a[30:23]; fa = a[22:0];
    sb = b[31]; eb = b[30:23]; fb = b[22:0];
    sy = sa ^ sb;
    a_nan = (ea == 8'hff) && (fa != 0);
    b_nan = (eb == 8'hff) && (fb != 0);
    a_inf = (ea == 8'hff) && (fa == 0);
    b_inf = (eb == 8'hff) && (fb == 0);
    a_zero = (ea == 0) && (fa == 0);
    b_zero = (eb == 0) && (fb == 0);
    y = 32'h0;
    ma = 0; mb = 0; prod = 0; m = 0; pw = 0; g = 0; st = 0; xa = 0; xb = 0; p = 0; i = 0; sh = 0; ef = 0;
    bits = 0;
    if (a_nan) y = a | 32'h0040_0000;
    else if (b_nan) y = b | 32'h0040_0000;
    else if ((a_inf && b_zero) || (b_inf && a_zero)) y = 32'hffc0_0000;
    else if (a_inf || b_inf) y = {sy, 8'hff, 23'h0};
    else if (a_zero || b_zero) y = {sy, 31'h0};
    else begin
      xa = (ea == 0) ? 1 : ea;
      xb = (eb == 0) ? 1 : eb;
      ma = {ea != 0, fa};
      mb = {eb != 0, fb};
      prod = ma * mb;  // value = prod * 2^(xa + xb - 254 - 46)
      p = 0;
      for (i = 0; i < 48; i = i + 1) if (prod[i]) p = i;
      sh = (p - 23 > 151 - xa - xb) ? p - 23 : 151 - xa - xb;
      ef = xa + xb + sh - 150;  // biased exponent of the unrounded result (1 for subnormals)
      pw = {16'b0, prod};
      if (sh > 63) begin
        // below a quarter of the smallest subnormal: rounds to zero
        m = 0; g = 0; st = 1;
      end else if (sh > 0) begin
        m = pw >> sh;
        g = pw[sh-1];
        st = ((pw << (65 - sh)) != 0);
      end else begin
        m = pw << (-sh);
        g = 0; st = 0;
      end
      if (g && (st || m[0])) m = m + 1;
      if (ef - 1 >= 255) y = {sy, 8'hff, 23'h0};
      else begin
        bits = ((ef - 1) << 23) + m;
        if (bits >= 64'h7f80_0000) y = {sy, 8'hff, 23'h0};
        else y = {sy, bits[30:0]};
      end
    end
  end
endmodule

// LATENCY-deep delay line of W-bit words (LATENCY = 0: a wire).
module fp_delay #(parameter integer LATENCY = 1, parameter integer W = 32) (
    input  wire         clk,
    input  wire [W-1:0] d,
    output wire [W-1:0] q
);
  generate
    if (LATENCY == 0) begin : g_wire
      assign q = d;
    end else begin : g_pipe
      reg [W-1:0] r [0:LATENCY-1];
      integer k;
      always @(posedge clk) begin
        r[0] <= d;
        for (k = 1; k < LATENCY; k = k + 1) r[k] <= r[k-1];
      end
      assign q = r[LATENCY-1];
    end
  endgenerate
endmodule

// The ADD PE's unit: y = sub ? a - b : a + b, LATENCY clocks after the operands.
module fp_add_sub #(parameter integer LATENCY = 10) (
    input  wire        clk,
    input  wire [31:0] a,
    input  wire [31:0] b,
    input  wire        sub,
    output wire [31:0] y
);
  wire [31:0] r;
  fp_add_sub_comb core (.a(a), .b(b), .sub(sub), .y(r));
  fp_delay #(.LATENCY(LATENCY)) line (.clk(clk), .d(r), .q(y));
endmodule

// The MULTI PE's unit: y = a * b, LATENCY clocks after the operands.
module fp_mul #(parameter integer LATENCY = 5) (
    input  wire        clk,
    input  wire [31:0] a,
    input  wire [31:0] b,
    output wire [31:0] y
);
  wire [31:0] r;
  fp_mul_comb core (.a(a), .b(b), .y(r));
  fp_delay #(.LATENCY(LATENCY)) line (.clk(clk), .d(r), .q(y));
endmodule
