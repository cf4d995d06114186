// robovec codegen<fpga>: the building blocks of the generated design (issue 12; seed §1.1, §1.3;
// SPEC §5). The generated top `robovec_top` instantiates `rv_pe` once per PE (ADD PEs first,
// then MULTI PEs, in `Pe::slot` order) and wires every PE's arriving result and buffer read
// into every PE's crossbar (`interconnect=crossbar`), or into the write ports whose program
// routes it (`interconnect=specialised`: each port's `src` bus holds its routes only).
//
// Timing (machine cycle k of the program = clock k of the run, counted from `start`):
//   * the instruction, crossbar, buffer-instruction and output-capture words of cycle k are
//     flip-flops during clock k: the control memory (block-RAM lanes in the top, shared by all
//     PEs) registers the word of cycle k at the edge ending clock k - 2 and the PE registers it
//     again at the next edge (rv_pe's `ctrl`; the buffer's read address of cycle k is used a clock early, from the block RAM's
//     output);
//   * during clock k the result of an op issued at k - LAT arrives (`result`, the register
//     after the crossbar: the seed's "+2" = one clock for the PE-memory read register, one for the
//     interconnect register); the buffer stores it (`store`) and is read (`read`, a store of the
//     same clock is seen: store before read); the crossbar selects up to two words for the PE
//     memory's two write ports; the output memory captures the arriving result;
//   * at the edge ending clock k the PE memory commits the writes and registers the two operand
//     reads of cycle k, write-first (a word written in cycle k is read in cycle k: the seed's
//     double-pumped M10K, `ir/src/placement.rs`);
//   * the floating-point unit takes the operands during clock k + 1 and has LAT - 2 stages, so
//     its result is in `result` during clock k + LAT.

// One PE: its control word (instruction, crossbar selects, buffer instruction, output capture,
// shift word: its bits of the control memory the top shares between all PEs, robovec's
// `Design::control_lanes`), PE memory, floating-point unit, buffer and output memory. Word
// layouts: see the manifest's `layout` and the `machine` module doc (LSB first).
module rv_pe #(
    parameter integer IS_MUL = 0,      // 0: ADD PE (fp_add_sub), 1: MULTI PE (fp_mul)
    parameter integer FIX = 0,         // 1: fixed-point PE (fix_add_sub / fix_mul, shift memory)
    parameter integer LVT = 0,         // 1: the PE memory as banks and a live-value table (rv_pe_mem_lvt)
    parameter integer MAC = 0,         // 1: fixed-point MULTI PE with fused multiply-adds (fix_mac): a third
                                       //    read (the addend) and PA + 2 more control bits after the shift word
    parameter integer DW = 32,         // data word bits (32 for binary32 PEs; fixed point: the widest format)
    parameter integer KW = 64,         // fixed-point PEs: bits of the exact intermediate (fix_units.v)
    parameter integer RMAX = 62,       // fixed-point ADD PEs: the program's largest floor (fix_add_sub)
    parameter integer AMAX = 63,       // fixed-point PEs: the program's largest alignment (ADD PEs: lift) (fix_units.v)
    parameter integer SMIN = -64,      // fixed-point PEs: the program's rounding shifts, SMIN..SMAX
    parameter integer SMAX = 63,
    parameter integer ONE = 27,        // fixed-point MULTI PEs: the widest word that is one DSP product (fix_units.v)
    parameter integer LAT = 12,        // cycles from issue to arrival (>= 3)
    parameter integer N0 = 4,          // sources of write port 0 (crossbar: 2 NPE)
    parameter integer SW0 = 3,         // its select bits
    parameter integer N1 = 4,          // sources of write port 1
    parameter integer SW1 = 3,         // its select bits
    parameter integer N2 = 0,          // sources of the shared multiplexer (0: none), whose output is
    parameter integer SW2 = 0,         // the last input of both ports (N0 + 1, N1 + 1); its select bits
    parameter integer AW = 11,         // PE memory address bits
    parameter integer BW = 4,          // buffer address bits
    parameter integer OW = 1,          // output memory address bits
    parameter integer MEM_DEPTH = 1,   // PE memory words
    parameter integer BUF_DEPTH = 1,   // buffer words
    parameter integer OUT_DEPTH = 1,   // output memory words
    parameter integer OUT_LUTRAM = 0,  // 1: the output memory in LUT RAM (rv_out_lutram: the Cyclone V's MLAB), else block RAM
    parameter integer PA = 11,         // bits of each address field of the control word (<= AW)
    parameter integer PB = BW,         // bits of each buffer address in the control word (<= BW)
    parameter integer PO = OW,         // bits of the output-memory address in the control word (<= OW)
    parameter integer FRB = 0,         // fixed-point ADD PEs: bits of the shift word's floor (0: never floors)
    parameter integer FAB = 6,         // fixed-point PEs: bits of the shift word's alignment (0: never aligns)
    parameter integer FALB = 1,        // fixed-point PEs: 1 when the shift word has the align-b bit
    parameter integer FSB = 7,         // fixed-point PEs: bits of the rounding shift less SMIN
    parameter integer CTW = 4 * PA + 4 + SW0 + SW1 + SW2 + 2 * PB + 2 + PO + 1 + (FIX != 0 ? FRB + FAB + FALB + FSB : 0) + (MAC != 0 ? PA + 2 : 0),  // control word bits
    parameter DATA_FILE = "",
    parameter OUT_FILE = ""
) (
    input  wire                 clk,
    input  wire                 run,       // executing cycle `pc` of the program
    input  wire [CTW-1:0]       ctrl_word, // this PE's bits of the control memory's output (robovec's
                                           // `Design::control_lanes`, read at `fetch` in the top): the word of the next cycle
    input  wire [DW*(N0 > 0 ? N0 : 1)-1:0] src0,  // port 0's sources (crossbar: {buffer reads, results})
    input  wire [DW*(N1 > 0 ? N1 : 1)-1:0] src1,  // port 1's sources
    input  wire [DW*(N2 > 0 ? N2 : 1)-1:0] src2,  // the shared multiplexer's sources
    output reg  [DW-1:0]        result,    // the result arriving this cycle
    output wire [DW-1:0]        buf_read,  // this cycle's buffer read
    input  wire [OW-1:0]        out_addr,  // output memory read port (its word on out_data a clock later)
    output wire [DW-1:0]        out_data
);
  localparam integer XW = SW0 + SW1 + SW2;
  localparam integer BIW = 2 * PB + 2;   // the buffer instruction in the control word
  localparam integer OCW = PO + 1;       // the capture word in the control word
  localparam integer FW = (FIX != 0) ? FRB + FAB + FALB + FSB : 0;  // the shift word in the control word

  // The block RAM's output is the word of the next cycle (`fetch` runs two cycles ahead of
  // the program): it is registered once more here, so that every field of the running cycle
  // leaves a flip-flop, not the block RAM's slow clock-to-output (5.6 ns on the ECP5's DP16KD,
  // the start of the critical path nextpnr reported), and the buffer's read address is known a
  // clock early (below).
  wire [CTW-1:0] ctrl_next = ctrl_word;
  reg  [CTW-1:0] ctrl;
  initial ctrl = 0;
  always @(posedge clk) ctrl <= ctrl_next;
  localparam integer IB = 4 * PA + 4;

  // instruction fields (the addresses zero-extended to the PE memory's AW bits)
  wire [AW-1:0] ra  = ctrl[PA-1:0];
  wire [AW-1:0] rb  = ctrl[2*PA-1:PA];
  wire [AW-1:0] wa0 = ctrl[3*PA-1:2*PA];
  wire [AW-1:0] wa1 = ctrl[4*PA-1:3*PA];
  wire          we0 = ctrl[4*PA] & run;
  wire          we1 = ctrl[4*PA+1] & run;
  wire          sub = ctrl[4*PA+3];
  wire [XW-1:0]  xbar = ctrl[IB +: XW];
  wire [BIW-1:0] bufi = ctrl[IB+XW +: BIW];
  wire [OCW-1:0] capt = ctrl[IB+XW+BIW +: OCW];

  // write-port selects, 0-based: word i of the port's sources (crossbar: 0..NPE-1 = result of
  // slot i, NPE..2NPE-1 = buffer read of slot i-NPE; a port with a shared multiplexer: its own
  // sources, then the shared output); we0/we1 say whether the port writes
  wire [SW0-1:0] sel0 = xbar[SW0-1:0];
  wire [SW1-1:0] sel1 = xbar[SW0+SW1-1:SW0];
  wire [DW-1:0] wd0, wd1;
  generate
    if (N2 > 0) begin : g_shared
      // the shared multiplexer (select N of a port of N own sources takes its output)
      wire [SW2-1:0] sel2 = xbar[XW-1:SW0+SW1];
      wire [DW-1:0] ys;
      rv_mux #(.N(N2), .SW(SW2), .DW(DW)) u_x2 (.sources(src2), .sel(sel2), .y(ys));
      wire [DW*(N0+1)-1:0] bus0;
      wire [DW*(N1+1)-1:0] bus1;
      if (N0 > 0) begin : g_b0
        assign bus0 = {ys, src0};
      end else begin : g_b0_only
        assign bus0 = ys;
      end
      if (N1 > 0) begin : g_b1
        assign bus1 = {ys, src1};
      end else begin : g_b1_only
        assign bus1 = ys;
      end
      rv_mux #(.N(N0 + 1), .SW(SW0), .DW(DW)) u_x0 (.sources(bus0), .sel(sel0), .y(wd0));
      rv_mux #(.N(N1 + 1), .SW(SW1), .DW(DW)) u_x1 (.sources(bus1), .sel(sel1), .y(wd1));
    end else begin : g_ports
      rv_mux #(.N(N0), .SW(SW0), .DW(DW)) u_x0 (.sources(src0), .sel(sel0), .y(wd0));
      rv_mux #(.N(N1), .SW(SW1), .DW(DW)) u_x1 (.sources(src1), .sel(sel1), .y(wd1));
    end
  endgenerate

  wire [DW-1:0] qa, qb, qc;
  // MAC PEs: the multiply-add's fields after the shift word (read address C, negate product, mac)
  localparam integer MB = IB + XW + BIW + OCW + FW;
  generate
    if (MAC != 0) begin : g_rc
      // The third read (the addend): a second copy of the PE memory taking the same writes, read
      // at rc with the same write-first forwarding (its second read port is left open).
      wire [AW-1:0] rc = ctrl[MB +: PA];
      if (LVT) begin : g_lvt
        rv_pe_mem_lvt #(.AW(AW), .DEPTH(MEM_DEPTH), .DW(DW), .FILE(DATA_FILE)) u_mem_c (
            .clk(clk), .we0(we0), .wa0(wa0), .wd0(wd0), .we1(we1), .wa1(wa1), .wd1(wd1),
            .ra(rc), .rb(rc), .qa(qc), .qb());
      end else begin : g_mem
        rv_pe_mem #(.AW(AW), .DEPTH(MEM_DEPTH), .DW(DW), .FILE(DATA_FILE)) u_mem_c (
            .clk(clk), .we0(we0), .wa0(wa0), .wd0(wd0), .we1(we1), .wa1(wa1), .wd1(wd1),
            .ra(rc), .rb(rc), .qa(qc), .qb());
      end
    end else begin : g_no_rc
      assign qc = {DW{1'b0}};
    end
    if (LVT) begin : g_lvt
      rv_pe_mem_lvt #(.AW(AW), .DEPTH(MEM_DEPTH), .DW(DW), .FILE(DATA_FILE)) u_mem (
          .clk(clk), .we0(we0), .wa0(wa0), .wd0(wd0), .we1(we1), .wa1(wa1), .wd1(wd1),
          .ra(ra), .rb(rb), .qa(qa), .qb(qb));
    end else begin : g_mem
      rv_pe_mem #(.AW(AW), .DEPTH(MEM_DEPTH), .DW(DW), .FILE(DATA_FILE)) u_mem (
          .clk(clk), .we0(we0), .wa0(wa0), .wd0(wd0), .we1(we1), .wa1(wa1), .wd1(wd1),
          .ra(ra), .rb(rb), .qa(qa), .qb(qb));
    end
  endgenerate

  reg sub_q;
  initial sub_q = 0;
  always @(posedge clk) sub_q <= sub;

  wire [DW-1:0] y;
  generate
    if (FIX != 0) begin : g_fix
      // the op's shift word, fetched with the instruction and registered with the operands:
      // the control word holds it cut to the PE's shifts (FRB floor bits on an ADD PE, FAB
      // alignment bits, the align-b bit when FALB, the rounding shift less SMIN in FSB bits),
      // widened back to the 20-bit word ([0,6) align, bit 6 align b, [7,14) s, [14,20) floor)
      // that the units read (fix_mul and fix_mac its low 14 bits)
      wire [FW-1:0] shf = ctrl[IB+XW+BIW+OCW +: FW];
      wire [5:0] fl;
      wire [5:0] al;
      wire       alb;
      if (FRB > 0) begin : g_fl
        assign fl = shf[FRB-1:0];
      end else begin : g_no_fl
        assign fl = 6'd0;
      end
      if (FAB > 0) begin : g_al
        assign al = shf[FRB+FAB-1:FRB];
      end else begin : g_no_al
        assign al = 6'd0;
      end
      if (FALB != 0) begin : g_alb
        assign alb = shf[FRB+FAB];
      end else begin : g_no_alb
        assign alb = 1'b0;
      end
      wire [7:0] s_off = shf[FW-1:FRB+FAB+FALB];
      wire [7:0] s_abs = s_off + SMIN;
      wire [19:0] sh = {fl, s_abs[6:0], alb, al};
      reg  [19:0] sh_q;
      initial sh_q = 0;
      always @(posedge clk) sh_q <= sh;
      if (IS_MUL != 0 && MAC != 0) begin : g_mac
        // negate product and mac, registered with the operands (sub_q negates the addend)
        reg negp_q, mac_q;
        initial begin
          negp_q = 0;
          mac_q = 0;
        end
        always @(posedge clk) begin
          negp_q <= ctrl[MB+PA];
          mac_q <= ctrl[MB+PA+1];
        end
        fix_mac #(.LATENCY(LAT - 2), .DW(DW), .KW(KW), .AMAX(AMAX), .SMIN(SMIN), .SMAX(SMAX), .ONE(ONE)) u_fx (
            .clk(clk), .a(qa), .b(qb), .c(qc), .mac(mac_q), .negp(negp_q), .sub(sub_q), .sh(sh_q[13:0]), .y(y));
      end else if (IS_MUL != 0) begin : g_mul
        fix_mul #(.LATENCY(LAT - 2), .DW(DW), .KW(KW), .SMIN(SMIN), .SMAX(SMAX), .ONE(ONE)) u_fx (.clk(clk), .a(qa), .b(qb), .sh(sh_q[13:0]), .y(y));
      end else begin : g_add
        fix_add_sub #(.LATENCY(LAT - 2), .DW(DW), .KW(KW), .RMAX(RMAX), .AMAX(AMAX), .SMIN(SMIN), .SMAX(SMAX)) u_fx (.clk(clk), .a(qa), .b(qb), .sub(sub_q), .sh(sh_q), .y(y));
      end
    end else if (IS_MUL != 0) begin : g_mul
      fp_mul #(.LATENCY(LAT - 2)) u_fp (.clk(clk), .a(qa), .b(qb), .y(y));
    end else begin : g_add
      fp_add_sub #(.LATENCY(LAT - 2)) u_fp (.clk(clk), .a(qa), .b(qb), .sub(sub_q), .y(y));
    end
  endgenerate

  // interconnect register: the result arrives one clock after the unit's last stage
  initial result = 0;
  always @(posedge clk) result <= y;

  // buffer: store the arriving result at `st`, read `rd` in the same clock (store first).
  // The read is fetched a clock early, from the next cycle's word, into flip-flops: `buf_q`
  // the word at `rd` before this clock's store, `res_q` this clock's result, `fwd_q` that this
  // clock stores to that address, `byp_q` that the next cycle does (its word is then that
  // cycle's `result`). So `buf_read` is a 3:1 choice between flip-flops (one 5-input LUT a
  // bit, as the 2:1 choice after the address decoding it replaces), not the buffer's address
  // decoding after the control memory's output (issue 49: the ECP5's critical path).
  // (the addresses zero-extended from the control word's PB bits)
  wire [BW-1:0] st    = bufi[PB-1:0];
  wire          st_en = bufi[2*PB] & run;
  wire [BIW-1:0] bufi_next = ctrl_next[IB+XW +: BIW];
  wire [BW-1:0] st_next = bufi_next[PB-1:0];
  wire [BW-1:0] rd_next = bufi_next[2*PB-1:PB];
  reg [DW-1:0] bmem [0:BUF_DEPTH-1];
  reg [DW-1:0] buf_q, res_q;
  reg          fwd_q, byp_q;
  initial begin
    buf_q = 0;
    res_q = 0;
    fwd_q = 0;
    byp_q = 0;
  end
  always @(posedge clk) begin
    if (st_en) bmem[st] <= result;
    buf_q <= bmem[rd_next];
    res_q <= result;
    fwd_q <= st_en && st == rd_next;
    byp_q <= bufi_next[2*PB] && st_next == rd_next;
  end
  assign buf_read = byp_q ? result : fwd_q ? res_q : buf_q;

  // output memory (rv_mem.v): captures the arriving result; read by the host after `done`
  wire [OW-1:0] oa   = capt[PO-1:0];
  wire          o_en = capt[PO] & run;
  generate
    if (OUT_LUTRAM != 0) begin : g_out_lutram
      rv_out_lutram #(.DW(DW), .DEPTH(OUT_DEPTH), .AW(OW), .FILE(OUT_FILE)) u_out (
          .clk(clk), .we(o_en), .wa(oa), .wd(result), .ra(out_addr), .q(out_data));
    end else begin : g_out_bram
      rv_out_mem #(.DW(DW), .DEPTH(OUT_DEPTH), .AW(OW), .FILE(OUT_FILE)) u_out (
          .clk(clk), .we(o_en), .wa(oa), .wd(result), .ra(out_addr), .q(out_data));
    end
  endgenerate
endmodule

// One write port's multiplexer: y = the DW-bit word `sel` (0-based) of `sources`, the last one
// for sel >= N (a crossbar port has N = 2 NPE sources, a specialised one its routes; the port's
// write enable, not a select code, says whether it writes). Written as a balanced tree of 2:1
// multiplexers on the bits of sel (level k decides on bit k) over 2^SW leaves, so that synthesis
// sees DW (2^SW - 1) multiplexers that it packs four data inputs to a LUT6, and not a variable
// shift of the whole bus (the form `sources[DW*sel +: DW]`, which Yosys maps as a barrel shifter
// first: its time exploded beyond 4 + 4 PEs). That form is what simulators read (no `SYNTHESIS`
// macro): the same word. The crossbar's ports share one module (parameters N and SW only): a
// hierarchical synthesis maps it once.
module rv_mux #(
    parameter integer N = 4,
    parameter integer SW = 2,
    parameter integer DW = 32
) (
    input  wire [DW*N-1:0] sources,
    input  wire [SW-1:0]   sel,
    output wire [DW-1:0]   y
);
  // `sel` is the 0-based index of the source (issue 49: no "none" code and no gate to zero; the
  // PE memory's write enable says whether the port writes, and a select beyond N - 1 reads the
  // last source). So 2^j sources take j select bits, and a LUT6 takes four of them a bit.
  localparam integer L = 1 << SW;
`ifdef SYNTHESIS
  // Level k + 1 of the tree from level k: word m chooses between words 2m and 2m + 1 by bit k
  // (upper words zero), one net a level.
  function [DW*L-1:0] level_up;
    input [DW*L-1:0] v;
    input b;
    integer m;
    begin
      level_up = {(DW*L){1'b0}};
      for (m = 0; m < L / 2; m = m + 1)
        level_up[DW*m +: DW] = b ? v[DW*(2*m+1) +: DW] : v[DW*(2*m) +: DW];
    end
  endfunction
  genvar k, j;
  generate
    for (k = 0; k <= SW; k = k + 1) begin : g_level
      wire [DW*L-1:0] v;
      if (k == 0) begin : g_leaves
        // the leaves: source j at word j, the last source again beyond N
        for (j = 0; j < L; j = j + 1) begin : g_leaf
          assign v[DW*j +: DW] = sources[DW*(j < N ? j : N - 1) +: DW];
        end
      end else begin : g_up
        assign v = level_up(g_level[k-1].v, sel[k-1]);
      end
    end
  endgenerate
  assign y = g_level[SW].v[DW-1:0];
`else
  // Simulators (Icarus, Verilator: no `SYNTHESIS`) read the same word directly. The tree's
  // forms cost them dearly on large designs: levels as slices of one net re-evaluated the whole
  // net on every change (the Jeep at 8 + 8 PEs simulated at 4 clocks a second), a wire per
  // node took Icarus minutes to elaborate at 144 PEs, a function per level 10x the run time.
  // `tests/fpga.rs` proves the two forms equal with Yosys.
  wire [SW:0] idx = sel < N ? {1'b0, sel} : N - 1;
  assign y = sources[DW*idx +: DW];
`endif
endmodule

// Program counter, start/done. `fetch` is the cycle whose control word the block RAMs register
// at the next edge (two ahead of `pc`); `run` is high during clocks 0..CYCLES of the program.
module rv_control #(
    parameter integer CW = 1,
    parameter integer CYCLES = 0
) (
    input  wire          clk,
    input  wire          rst,
    input  wire          start,
    output reg           run,
    output reg           done,
    output reg  [CW-1:0] pc,
    output wire [CW-1:0] fetch
);
  // Two cycles ahead: the control memories' block RAMs register the word of cycle pc + 2 at
  // the edge ending cycle pc and the PE registers it once more (rv_pe's `ctrl`). While idle the
  // word of cycle 0 is fetched, and that of cycle 1 in the clock `start` is high; the last
  // cycle fetches cycle 0 again, so that a program can start at the clock after `done`.
  assign fetch = run ? (pc == CYCLES ? {CW{1'b0}} : pc + 2'd2) : (start ? {CW{1'b0}} + 1'b1 : {CW{1'b0}});
  initial begin
    run = 0;
    done = 0;
    pc = 0;
  end
  always @(posedge clk) begin
    if (rst) begin
      run <= 0;
      done <= 0;
      pc <= 0;
    end else if (!run && start) begin
      run <= 1;
      done <= 0;
      pc <= 0;
    end else if (run) begin
      if (pc == CYCLES) begin
        run <= 0;
        done <= 1;
      end else pc <= pc + 1'b1;
    end
  end
endmodule

// Output memory in LUT RAM (`OUT_LUTRAM`, the Cyclone V's MLAB, issue 49): rv_mem.v's `rv_out_mem` for a
// memory of at most 32 words without initial contents (every word it gives the host was
// captured during the run). A few ALMs instead of an M10K: Yosys `synth_intel_alm` maps it to
// MISTRAL_MLAB cells (32 words x 1 bit) and the read register; Quartus to an MLAB by the
// attribute. Here, not in rv_mem.v: the resource estimate's Yosys run synthesises it (rv_mem.v's
// block RAMs are black boxes there).
module rv_out_lutram #(
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
  (* ramstyle = "MLAB" *) reg [DW-1:0] mem [0:DEPTH-1];
  initial q = 0;
`ifndef SYNTHESIS
  // (simulators: zeros, as the block RAM's; synthesis: no initial contents, which Yosys 0.23
  // would not map to MLAB cells)
  integer i;
  initial for (i = 0; i < DEPTH; i = i + 1) mem[i] = 0;
`endif
  always @(posedge clk) begin
    if (we) mem[wa] <= wd;
    q <= mem[ra];
  end
endmodule
