// What this core's FP units give: throughput of 512- and 256-bit FMA, add,
// multiply, division and square root over 12 independent register chains,
// and one FMA's latency (a single chain). Used to read the sphere kernel's
// profile (reports/performance.md, "The slot's dependency chain"): the pair
// pass runs far below these rates, so it is not bound by them.
//   gcc -O2 -march=x86-64-v4 bench/fp_units.c -o /tmp/fp_units && taskset -c 0 /tmp/fp_units
// (x86-64 with AVX-512 only; the empty asm keeps each value in a register.)
#include <immintrin.h>
#include <stdio.h>
#include <time.h>
static double now() {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}
#define DECL(T, S)                                                                             \
  T a0 = S(1.0), a1 = S(1.1), a2 = S(1.2), a3 = S(1.3), a4 = S(1.4), a5 = S(1.5), a6 = S(1.6), \
    a7 = S(1.7), a8 = S(1.8), a9 = S(1.9), a10 = S(2.0), a11 = S(2.1);
#define ALL(OP) \
  OP(a0);       \
  OP(a1);       \
  OP(a2);       \
  OP(a3);       \
  OP(a4);       \
  OP(a5);       \
  OP(a6);       \
  OP(a7);       \
  OP(a8);       \
  OP(a9);       \
  OP(a10);      \
  OP(a11);

int main() {
  const long N = 20000000;
  double t0, t1, s;
  {
    DECL(__m512d, _mm512_set1_pd) __m512d m = _mm512_set1_pd(0.999999999), c = _mm512_set1_pd(1e-9);
#define F(x) x = _mm512_fmadd_pd(x, m, c)
    t0 = now();
    for (long i = 0; i < N; i++) {
      ALL(F)
      __asm__ volatile("" ::"v"(a0), "v"(a1), "v"(a2), "v"(a3), "v"(a4), "v"(a5), "v"(a6), "v"(a7),
                       "v"(a8), "v"(a9), "v"(a10), "v"(a11));
    }
    t1 = now();
    s = a0[0] + a11[0];
    printf("zmm fma: %.3f /ns %g\n", 12.0 * N / (t1 - t0) / 1e9, s);
#define A(x) x = _mm512_add_pd(x, c)
    t0 = now();
    for (long i = 0; i < N; i++) {
      ALL(A)
      __asm__ volatile("" ::"v"(a0), "v"(a1), "v"(a2), "v"(a3), "v"(a4), "v"(a5), "v"(a6), "v"(a7),
                       "v"(a8), "v"(a9), "v"(a10), "v"(a11));
    }
    t1 = now();
    s = a0[0] + a11[0];
    printf("zmm add: %.3f /ns %g\n", 12.0 * N / (t1 - t0) / 1e9, s);
#define MU(x) x = _mm512_mul_pd(x, m)
    t0 = now();
    for (long i = 0; i < N; i++) {
      ALL(MU)
      __asm__ volatile("" ::"v"(a0), "v"(a1), "v"(a2), "v"(a3), "v"(a4), "v"(a5), "v"(a6), "v"(a7),
                       "v"(a8), "v"(a9), "v"(a10), "v"(a11));
    }
    t1 = now();
    s = a0[0] + a11[0];
    printf("zmm mul: %.3f /ns %g\n", 12.0 * N / (t1 - t0) / 1e9, s);
    __m512d x = a0;
    t0 = now();
    for (long i = 0; i < N; i++) {
      x = _mm512_fmadd_pd(x, m, c);
      __asm__ volatile("" ::"v"(x));
    }
    t1 = now();
    printf("zmm fma latency: %.3f ns %g\n", (t1 - t0) / N * 1e9, x[0]);
#define DV(x) x = _mm512_div_pd(m, x)
    t0 = now();
    for (long i = 0; i < N / 10; i++) {
      ALL(DV)
      __asm__ volatile("" ::"v"(a0), "v"(a1), "v"(a2), "v"(a3), "v"(a4), "v"(a5), "v"(a6), "v"(a7),
                       "v"(a8), "v"(a9), "v"(a10), "v"(a11));
    }
    t1 = now();
    s = a0[0] + a11[0];
    printf("zmm div: %.3f /ns %g\n", 12.0 * N / 10 / (t1 - t0) / 1e9, s);
#define SQ(x) x = _mm512_sqrt_pd(x)
    t0 = now();
    for (long i = 0; i < N / 10; i++) {
      ALL(SQ)
      __asm__ volatile("" ::"v"(a0), "v"(a1), "v"(a2), "v"(a3), "v"(a4), "v"(a5), "v"(a6), "v"(a7),
                       "v"(a8), "v"(a9), "v"(a10), "v"(a11));
    }
    t1 = now();
    s = a0[0] + a11[0];
    printf("zmm sqrt: %.3f /ns %g\n", 12.0 * N / 10 / (t1 - t0) / 1e9, s);
  }
  {
    DECL(__m256d, _mm256_set1_pd) __m256d m = _mm256_set1_pd(0.999999999), c = _mm256_set1_pd(1e-9);
#define F2(x) x = _mm256_fmadd_pd(x, m, c)
    t0 = now();
    for (long i = 0; i < N; i++) {
      ALL(F2)
      __asm__ volatile("" ::"x"(a0), "x"(a1), "x"(a2), "x"(a3), "x"(a4), "x"(a5), "x"(a6), "x"(a7),
                       "x"(a8), "x"(a9), "x"(a10), "x"(a11));
    }
    t1 = now();
    s = a0[0] + a11[0];
    printf("ymm fma: %.3f /ns %g\n", 12.0 * N / (t1 - t0) / 1e9, s);
#define A2(x) x = _mm256_add_pd(x, c)
    t0 = now();
    for (long i = 0; i < N; i++) {
      ALL(A2)
      __asm__ volatile("" ::"x"(a0), "x"(a1), "x"(a2), "x"(a3), "x"(a4), "x"(a5), "x"(a6), "x"(a7),
                       "x"(a8), "x"(a9), "x"(a10), "x"(a11));
    }
    t1 = now();
    s = a0[0] + a11[0];
    printf("ymm add: %.3f /ns %g\n", 12.0 * N / (t1 - t0) / 1e9, s);
#define DV2(x) x = _mm256_div_pd(m, x)
    t0 = now();
    for (long i = 0; i < N / 10; i++) {
      ALL(DV2)
      __asm__ volatile("" ::"x"(a0), "x"(a1), "x"(a2), "x"(a3), "x"(a4), "x"(a5), "x"(a6), "x"(a7),
                       "x"(a8), "x"(a9), "x"(a10), "x"(a11));
    }
    t1 = now();
    s = a0[0] + a11[0];
    printf("ymm div: %.3f /ns %g\n", 12.0 * N / 10 / (t1 - t0) / 1e9, s);
#define SQ2(x) x = _mm256_sqrt_pd(x)
    t0 = now();
    for (long i = 0; i < N / 10; i++) {
      ALL(SQ2)
      __asm__ volatile("" ::"x"(a0), "x"(a1), "x"(a2), "x"(a3), "x"(a4), "x"(a5), "x"(a6), "x"(a7),
                       "x"(a8), "x"(a9), "x"(a10), "x"(a11));
    }
    t1 = now();
    s = a0[0] + a11[0];
    printf("ymm sqrt: %.3f /ns %g\n", 12.0 * N / 10 / (t1 - t0) / 1e9, s);
  }
}
