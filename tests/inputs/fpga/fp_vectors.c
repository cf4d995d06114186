/* Test vectors for codegen<fpga>'s fp_add_sub / fp_mul models (tests/fpga.rs): random and edge
 * operand pairs with the result of C `float` arithmetic (x86-64 SSE, as Rust's f32), one line
 * per vector: op (0 add, 1 sub, 2 mul), a, b, expected, as 4 hex words for $readmemh.
 * Operand kinds: any bit pattern, moderate exponents, subnormals, close exponents (cancellation),
 * near-negations, edge values (zeros, subnormal/normal boundary, max, inf, NaN), extremes.
 * Every pair of edge values is included. Build with -ffp-contract=off. */
#include <stdio.h>
#include <stdint.h>
#include <string.h>
#include <stdlib.h>
static uint64_t st = 88172645463325252ull;
static uint32_t rnd(void){ st ^= st<<13; st ^= st>>7; st ^= st<<17; return (uint32_t)(st>>16); }
static float f(uint32_t u){ float x; memcpy(&x,&u,4); return x; }
static uint32_t u(float x){ uint32_t v; memcpy(&v,&x,4); return v; }
static const uint32_t edge[] = {0,0x80000000,1,0x80000001,0x007fffff,0x807fffff,0x00800000,0x80800000,
 0x00800001,0x3f800000,0xbf800000,0x3f800001,0x3f7fffff,0x7f7fffff,0xff7fffff,0x7f800000,0xff800000,
 0x7fc00000,0xffc00000,0x7f800001,0x7fa00000,0x33800000,0x34000000,0x4b800000,0x00400000,0x3f000000};
static uint32_t operand(int kind, uint32_t other){
  uint32_t r = rnd();
  switch(kind){
  case 0: return r;                                   /* any bit pattern */
  case 1: return (r & 0x807fffff) | ((uint32_t)(100 + rnd()%56) << 23); /* moderate */
  case 2: return r & 0x807fffff;                      /* subnormal */
  case 3: { int e = ((other>>23)&0xff) + (int)(rnd()%5) - 2; if(e<0)e=0; if(e>254)e=254;
            return (r & 0x807fffff) | ((uint32_t)e<<23); }  /* close exponent: cancellation */
  case 4: return (other ^ 0x80000000) + (rnd()%7) - 3;   /* near-negation */
  case 5: return edge[rnd()%(sizeof edge/sizeof edge[0])];
  default: { int e = rnd()%40; if (rnd()&1) e = 254 - e; return (r & 0x807fffff) | ((uint32_t)e<<23);} /* extremes */
  }
}
int main(int argc, char **argv){
  int n = argc > 1 ? atoi(argv[1]) : 10000;
  for (int i = 0; i < n; i++) {
    int op = rnd()%3; /* 0 add, 1 sub, 2 mul */
    uint32_t a = operand(rnd()%7, 0x3f800000);
    uint32_t b = operand(rnd()%7, a);
    volatile float fa = f(a), fb = f(b);
    float y = op==0 ? fa+fb : op==1 ? fa-fb : fa*fb;
    printf("%08x%08x%08x%08x\n", (unsigned)op, a, b, u(y));
  }
  for (unsigned i = 0; i < sizeof edge/sizeof edge[0]; i++)
    for (unsigned j = 0; j < sizeof edge/sizeof edge[0]; j++)
      for (int op = 0; op < 3; op++) {
        volatile float fa = f(edge[i]), fb = f(edge[j]);
        float y = op==0 ? fa+fb : op==1 ? fa-fb : fa*fb;
        printf("%08x%08x%08x%08x\n", (unsigned)op, edge[i], edge[j], u(y));
      }
  return 0;
}
