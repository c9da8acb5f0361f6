/* Times FMM3D's Laplace FMM (lfmm3d_s_c_g: potential and gradient of point
 * charges) through its C interface, for tools/bench_gravity_peers.py: the
 * library built from source with its vectorised kernels (make lib
 * FAST_KER=ON), which the Python wheel's build does not offer.
 *
 *   fmm3d_driver IN EPS REPEATS OUT
 * IN: int64 n, then n·3 doubles (x, y, z of each source), then n doubles
 * (charges). Runs one untimed evaluation, then REPEATS timed ones; prints
 * the median wall seconds; writes the last gradient (n·3 doubles) to OUT.
 *
 * Build (FMM3D's static library and its C header):
 *   gcc -O2 -std=c99 -Wall tools/peers/fmm3d_driver.c -I$FMM3D/c $FMM3D/lib-static/libfmm3d.a \
 *       -lgfortran -lstdc++ -lgomp -lm -o /tmp/fmm3d_driver
 */
#define _POSIX_C_SOURCE 199309L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

void lfmm3d_s_c_g_(double *eps, int64_t *nsource, double *source, double *charge, double *pot, double *grad,
                   int64_t *ier);

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int by_value(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

int main(int argc, char **argv) {
  if (argc != 5) {
    fprintf(stderr, "usage: %s IN EPS REPEATS OUT\n", argv[0]);
    return 2;
  }
  FILE *in = fopen(argv[1], "rb");
  int64_t n = 0;
  if (!in || fread(&n, sizeof n, 1, in) != 1 || n < 1) {
    fprintf(stderr, "%s: cannot read the particle count\n", argv[1]);
    return 1;
  }
  double *src = malloc(sizeof(double) * 3 * (size_t)n), *q = malloc(sizeof(double) * (size_t)n);
  double *pot = malloc(sizeof(double) * (size_t)n), *grad = malloc(sizeof(double) * 3 * (size_t)n);
  if (!src || !q || !pot || !grad || fread(src, sizeof(double), 3 * (size_t)n, in) != 3 * (size_t)n ||
      fread(q, sizeof(double), (size_t)n, in) != (size_t)n) {
    fprintf(stderr, "%s: short file\n", argv[1]);
    return 1;
  }
  fclose(in);
  double eps = atof(argv[2]);
  const int repeats = atoi(argv[3]);
  if (repeats < 1) return 2;
  double *times = malloc(sizeof(double) * (size_t)repeats);
  int64_t ier = 0;
  lfmm3d_s_c_g_(&eps, &n, src, q, pot, grad, &ier); /* warm-up */
  for (int r = 0; r < repeats; ++r) {
    const double t0 = now();
    lfmm3d_s_c_g_(&eps, &n, src, q, pot, grad, &ier);
    times[r] = now() - t0;
  }
  if (ier != 0) {
    fprintf(stderr, "lfmm3d: ier = %ld\n", (long)ier);
    return 1;
  }
  qsort(times, (size_t)repeats, sizeof(double), by_value);
  FILE *out = fopen(argv[4], "wb");
  if (!out || fwrite(grad, sizeof(double), 3 * (size_t)n, out) != 3 * (size_t)n) return 1;
  fclose(out);
  printf("%.9f\n", repeats % 2 ? times[repeats / 2] : 0.5 * (times[repeats / 2 - 1] + times[repeats / 2]));
  return 0;
}
