// Checks the combinational cores of fp_add_sub and fp_mul against the vectors of fp_vectors.c
// (tests/fpga.rs): every result bit for bit; prints "checked N vectors, M mismatches".
`timescale 1ns/1ps
module tb;
  reg [127:0] vec [0:`N-1];
  reg [31:0] a, b; reg sub; integer i, bad, nan_ok;
  wire [31:0] ys, ym;
  fp_add_sub_comb A(.a(a), .b(b), .sub(sub), .y(ys));
  fp_mul_comb M(.a(a), .b(b), .y(ym));
  reg [31:0] got, want;
  initial begin
    $readmemh(`VEC, vec);
    bad = 0;
    for (i = 0; i < `N; i = i + 1) begin
      a = vec[i][95:64]; b = vec[i][63:32]; sub = (vec[i][127:96] == 1); want = vec[i][31:0];
      #1;
      got = (vec[i][127:96] == 2) ? ym : ys;
      if (got !== want) begin
        bad = bad + 1;
        if (bad < 20) $display("MISMATCH op=%0d a=%h b=%h got=%h want=%h", vec[i][127:96], a, b, got, want);
      end
    end
    $display("checked %0d vectors, %0d mismatches", `N, bad);
    $finish;
  end
endmodule
