/* Plain C reference of the N-DOF kernel's default mode (same RK4, same tabulated coefficients).
 *
 * Reads a batch written by benchmarks/w4.py (text: n M H P, then per point omega Tf N, A (n*n),
 * B (n*n), W (M*n), V (M*n), g (n), D (M), ratio (M), coef (M*3*(H+1)*2), x0 (2n)), integrates
 * every point through TRANSIENT + RECORD forcing periods with fixed-step RK4 (h = Tf/N), keeps
 * min/max of every mesh deflection over the recorded periods, and prints the wall time and a
 * checksum.  Build: gcc -O3 -march=native -o ref_ndof ref_ndof.c -lm
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define MAXN 32
#define MAXM 8

static int n, M, H, P, NT, NR;

static double fz(double u, double D) { double c = u < -D ? -D : (u > D ? D : u); return u - c; }

static void field(const double *x, const double *cf, const double *A, const double *B, const double *W,
                  const double *V, const double *D, const double *g, double om, double *out) {
    for (int i = 0; i < n; i++) out[i] = x[n + i];
    for (int i = 0; i < n; i++) {
        double acc = g[i];
        for (int j = 0; j < n; j++) acc -= A[i * n + j] * x[j] + B[i * n + j] * x[n + j];
        out[n + i] = acc;
    }
    for (int m = 0; m < M; m++) {
        double d = 0, dv = 0;
        for (int j = 0; j < n; j++) { d += V[m * n + j] * x[j]; dv += V[m * n + j] * x[n + j]; }
        d -= cf[m * 4 + 2];
        dv -= om * cf[m * 4 + 3];
        double s = cf[m * 4 + 0] * dv + cf[m * 4 + 1] * fz(d, D[m]);
        for (int i = 0; i < n; i++) out[n + i] -= W[m * n + i] * s;
    }
}

static void coef_at(const double *coef, const double *ratio, double th, double *out) {
    for (int m = 0; m < M; m++) {
        const double *c = coef + m * 3 * (H + 1) * 2;
        double ph = ratio[m] * th, C = c[0], K = c[(H + 1) * 2], E = c[2 * (H + 1) * 2], Ed = 0;
        for (int j = 1; j <= H; j++) {
            double cj = cos(j * ph), sj = sin(j * ph);
            C += c[j * 2] * cj + c[j * 2 + 1] * sj;
            K += c[(H + 1) * 2 + j * 2] * cj + c[(H + 1) * 2 + j * 2 + 1] * sj;
            E += c[2 * (H + 1) * 2 + j * 2] * cj + c[2 * (H + 1) * 2 + j * 2 + 1] * sj;
            Ed += j * ratio[m] * (c[2 * (H + 1) * 2 + j * 2 + 1] * cj - c[2 * (H + 1) * 2 + j * 2] * sj);
        }
        out[m * 4] = C; out[m * 4 + 1] = K; out[m * 4 + 2] = E; out[m * 4 + 3] = Ed;
    }
}

static double rd(FILE *f) { double v; if (fscanf(f, "%lf", &v) != 1) { fprintf(stderr, "bad input\n"); exit(2); } return v; }

int main(int argc, char **argv) {
    if (argc < 4) { fprintf(stderr, "usage: ref_ndof FILE TRANSIENT RECORD\n"); return 2; }
    FILE *f = fopen(argv[1], "r");
    NT = atoi(argv[2]); NR = atoi(argv[3]);
    n = (int)rd(f); M = (int)rd(f); H = (int)rd(f); P = (int)rd(f);
    int d = 2 * n, nc = M * 3 * (H + 1) * 2;
    double *all = malloc(sizeof(double) * P * (3 + 2 * n * n + 2 * M * n + n + 2 * M + nc + d));
    double *p0 = all;
    for (long i = 0; i < (long)P * (3 + 2 * n * n + 2 * M * n + n + 2 * M + nc + d); i++) all[i] = rd(f);
    fclose(f);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    double checksum = 0;
    for (int p = 0; p < P; p++) {
        double om = p0[0], Tf = p0[1]; int N = (int)p0[2];
        double *A = p0 + 3, *B = A + n * n, *W = B + n * n, *V = W + M * n, *g = V + M * n, *D = g + n,
               *ratio = D + M, *coef = ratio + M, *x0 = coef + nc;
        p0 = x0 + d;
        double h = Tf / N, hh = 0.5 * h, h6 = h / 6.0;
        double *tab = malloc(sizeof(double) * (2 * N + 1) * M * 4);
        for (int i = 0; i <= 2 * N; i++) coef_at(coef, ratio, om * (0.5 * h * i), tab + i * M * 4);
        double x[2 * MAXN], xs[2 * MAXN], k1[2 * MAXN], k2[2 * MAXN], k3[2 * MAXN], k4[2 * MAXN];
        double umin[MAXM], umax[MAXM];
        for (int i = 0; i < d; i++) x[i] = x0[i];
        for (int m = 0; m < M; m++) { umin[m] = INFINITY; umax[m] = -INFINITY; }
        for (int per = 0; per < NT + NR; per++) {
            for (int j = 0; j < N; j++) {
                const double *c0 = tab + (2 * j) * M * 4, *c1 = c0 + M * 4, *c2 = c1 + M * 4;
                field(x, c0, A, B, W, V, D, g, om, k1);
                for (int i = 0; i < d; i++) xs[i] = x[i] + hh * k1[i];
                field(xs, c1, A, B, W, V, D, g, om, k2);
                for (int i = 0; i < d; i++) xs[i] = x[i] + hh * k2[i];
                field(xs, c1, A, B, W, V, D, g, om, k3);
                for (int i = 0; i < d; i++) xs[i] = x[i] + h * k3[i];
                field(xs, c2, A, B, W, V, D, g, om, k4);
                for (int i = 0; i < d; i++) x[i] += h6 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
                if (per >= NT) {
                    for (int m = 0; m < M; m++) {
                        double dd = -c2[m * 4 + 2];
                        for (int i = 0; i < n; i++) dd += V[m * n + i] * x[i];
                        if (dd < umin[m]) umin[m] = dd;
                        if (dd > umax[m]) umax[m] = dd;
                    }
                }
            }
        }
        for (int m = 0; m < M; m++) checksum += umin[m] + umax[m];
        free(tab);
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    printf("%.6f %.12e\n", (t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec), checksum);
    free(all);
    return 0;
}
