/* Reference for `fkopt bench --section cases`: GABC on the 3-RPS forward kinematics as a plain
 * C loop, one run after the other, to time against fkopt's batched numpy engine.
 *
 * The same algorithm and problem as fkopt.solve(fk_problem(ThreeRPS(), joints), "gabc"):
 *   - 3-RPS of mao2017 (r_a = 274 mm, r_b = 158 mm), pose (alpha, beta, z) in
 *     [-20, 20] deg x [-20, 20] deg x [400, 700] mm; leg lengths by the same lean evaluation as
 *     fkopt/mechanisms/rps3.py ThreeRPS.ik (half-angle tangents, eq. 10 with eq. 6 substituted);
 *     fitness = sum of squared leg-length residuals (mao2017 eq. 12);
 *   - GABC, rule mao2017 eq. 19: v_j = x_j + phi (x_j - x_kj) + phi (best_j - x_kj), one random
 *     coordinate j, k != i, phi ~ U[-1, 1], clipped to the bounds; greedy selection on raw f;
 *     onlooker roulette on fit = 1/(1+f); limit = SN * dim; per iteration a scout (the source
 *     with most trials, if above limit, evaluated with the employed bees), the employed phase,
 *     the best-so-far update, the onlooker phase, the best-so-far update.
 * ABC (algorithm "abc"): the same loop with Karaboga's move v_j = x_j + phi (x_j - x_kj).
 * PSO (algorithm "pso", fkopt/algorithms/pso.py defaults): global best, w = 0.7298,
 *   c1 = c2 = 1.49618, velocity clamp 0.2 x box width per coordinate, positions clipped onto the
 *   box and the velocity component that hit it set to zero, initial velocities zero, gbest read
 *   once per iteration; population evaluations per iteration.
 * Differences that do not change the cost per evaluation: onlookers act one after the other
 * (Karaboga's loop; fkopt resolves them synchronously), and the random numbers come from a
 * PCG64 (XSL-RR 128/64, the generator numpy uses) seeded here by splitmix64, so the numbers
 * are not fkopt's.
 *
 * Usage: gabc_3rps ITERATIONS POPULATION RUNS SEED [gabc|abc|pso] < joints   (one "d1 d2 d3" line
 * per case; the algorithm defaults to gabc)
 * Prints one line: "evaluations seconds median_final_fitness max_final_fitness cpu_seconds", where
 * seconds covers the solves only (clock_gettime, CLOCK_MONOTONIC), not reading the input, and
 * cpu_seconds the same span in this process's CPU time (CLOCK_PROCESS_CPUTIME_ID: what a busy
 * shared machine disturbs least).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define DIM 3
#define MAXPOP 1024

static const double LO[DIM] = {-20.0, -20.0, 400.0};
static const double HI[DIM] = {20.0, 20.0, 700.0};
static const double RA = 274.0, RB = 158.0;
enum { GABC, ABC, PSO };
static int algorithm = GABC;

/* -- PCG64 (XSL-RR 128/64) ------------------------------------------------------------------ */
typedef struct { __uint128_t state, inc; } pcg64;

static uint64_t splitmix64(uint64_t *s) {
    uint64_t z = (*s += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

static uint64_t pcg64_next(pcg64 *g) {
    const __uint128_t mult = ((__uint128_t)2549297995355413924ULL << 64) | 4865540595714422341ULL;
    g->state = g->state * mult + g->inc;
    uint64_t hi = (uint64_t)(g->state >> 64), lo = (uint64_t)g->state;
    unsigned rot = (unsigned)(hi >> 58);
    uint64_t x = hi ^ lo;
    return (x >> rot) | (x << ((-rot) & 63));
}

static void pcg64_seed(pcg64 *g, uint64_t seed, uint64_t stream) {
    uint64_t s = seed * 0x100000001B3ULL ^ stream;
    __uint128_t init = ((__uint128_t)splitmix64(&s) << 64) | splitmix64(&s);
    __uint128_t seq = ((__uint128_t)splitmix64(&s) << 64) | splitmix64(&s);
    g->state = 0;
    g->inc = (seq << 1) | 1;
    pcg64_next(g);
    g->state += init;
    pcg64_next(g);
}

static inline double uniform(pcg64 *g) { return (pcg64_next(g) >> 11) * (1.0 / 9007199254740992.0); }

/* -- 3-RPS fitness: ThreeRPS.ik's lean form, then the sum of squared residuals -------------- */
static double fitness(const double *x, const double *joints) {
    const double half = M_PI / 360.0, s3 = 0.5 * sqrt(3.0);
    double ta = tan(x[0] * half), tb = tan(x[1] * half), z = x[2];
    double ra_ = 1.0 / (1.0 + ta * ta), rb_ = 1.0 / (1.0 + tb * tb);
    double sa = (ta + ta) * ra_, ca = (1.0 - ta * ta) * ra_;
    double sb = (tb + tb) * rb_, cb = (1.0 - tb * tb) * rb_;
    double sbsa = sb * sa;
    double tg = sbsa / (ca + cb);
    double cg = 1.0 / sqrt(1.0 + tg * tg), sg = tg * cg;
    double R00 = cg * cb, R10 = sg * cb, R11 = sg * sbsa + cg * ca, R01 = cg * sbsa - sg * ca;
    double h = (0.5 * RB) * R11;
    double e = (1.5 * RB) * R00 - h - RA, f = z - RB * sb;
    double d1 = sqrt(e * e + f * f);
    double ax = 0.5 * RA - h, bx = (s3 * RB) * R01, ay = (-1.5 * RB) * R10, by = (-2.0 * s3) * ax;
    double az = z + (0.5 * RB) * sb, bz = (s3 * RB) * (cb * sa);
    double u = ax + bx, v = ay + by, w = az + bz;
    double d2 = sqrt(u * u + v * v + w * w);
    u = ax - bx; v = ay - by; w = az - bz;
    double d3 = sqrt(u * u + v * v + w * w);
    double r1 = d1 - joints[0], r2 = d2 - joints[1], r3 = d3 - joints[2];
    double out = r1 * r1 + r2 * r2 + r3 * r3;
    return isnan(out) ? INFINITY : out;
}

/* -- GABC, one run -------------------------------------------------------------------------- */
typedef struct {
    double x[MAXPOP][DIM], f[MAXPOP], cdf[MAXPOP], best_x[DIM], best_f;
    long trial[MAXPOP];
} colony;

static inline double quality(double f) { return f >= 0 ? 1.0 / (1.0 + f) : 1.0 - f; }

static void update_best(colony *c, int sn) {
    for (int i = 0; i < sn; i++)
        if (c->f[i] < c->best_f) {
            c->best_f = c->f[i];
            for (int d = 0; d < DIM; d++) c->best_x[d] = c->x[i][d];
        }
}

/* Candidate of source i (neighbour move of GABC) and its greedy selection. */
static void try_move(colony *c, int i, int sn, pcg64 *g, const double *joints) {
    int j = (int)(uniform(g) * DIM);
    int k = (int)(uniform(g) * (sn - 1));
    k += k >= i;
    double phi = 2.0 * uniform(g) - 1.0;
    double v[DIM] = {c->x[i][0], c->x[i][1], c->x[i][2]};
    double m = algorithm == ABC ? v[j] + phi * (v[j] - c->x[k][j])
                                : v[j] + (phi * (v[j] - c->x[k][j]) + phi * (c->best_x[j] - c->x[k][j]));
    v[j] = m < LO[j] ? LO[j] : (m > HI[j] ? HI[j] : m);
    double fv = fitness(v, joints);
    if (fv < c->f[i]) {
        c->x[i][j] = v[j];
        c->f[i] = fv;
        c->trial[i] = 0;
    } else {
        c->trial[i]++;
    }
}

static double gabc_run(int iterations, int sn, pcg64 *g, const double *joints, long *evals) {
    static colony c;
    long limit = (long)sn * DIM;
    for (int i = 0; i < sn; i++) {
        for (int d = 0; d < DIM; d++) c.x[i][d] = LO[d] + uniform(g) * (HI[d] - LO[d]);
        c.f[i] = fitness(c.x[i], joints);
        c.trial[i] = 0;
    }
    *evals += sn;
    c.best_f = INFINITY;
    update_best(&c, sn);
    for (int t = 1; t <= iterations; t++) {
        double fresh[DIM];                     /* scout: drawn every iteration */
        for (int d = 0; d < DIM; d++) fresh[d] = LO[d] + uniform(g) * (HI[d] - LO[d]);
        int worst = 0;
        for (int i = 1; i < sn; i++) if (c.trial[i] > c.trial[worst]) worst = i;
        if (c.trial[worst] > limit) {
            for (int d = 0; d < DIM; d++) c.x[worst][d] = fresh[d];
            c.f[worst] = fitness(fresh, joints);
            c.trial[worst] = 0;
            (*evals)++;
        }
        for (int i = 0; i < sn; i++) try_move(&c, i, sn, g, joints);      /* employed */
        *evals += sn;
        update_best(&c, sn);
        double total = 0.0;                    /* onlookers: roulette on fit = 1/(1+f) */
        for (int i = 0; i < sn; i++) { total += quality(c.f[i]); c.cdf[i] = total; }
        for (int m = 0; m < sn; m++) {
            double u = uniform(g) * total;
            int i = 0;
            while (i < sn && c.cdf[i] <= u) i++;
            if (i == sn) i = 0;
            try_move(&c, i, sn, g, joints);
        }
        *evals += sn;
        update_best(&c, sn);
    }
    return c.best_f;
}

/* -- PSO, one run ---------------------------------------------------------------------------- */
static double pso_run(int iterations, int n, pcg64 *g, const double *joints, long *evals) {
    static double pos[MAXPOP][DIM], vel[MAXPOP][DIM], px[MAXPOP][DIM], pf[MAXPOP];
    const double w = 0.7298, c1 = 1.49618, c2 = 1.49618;
    double vmax[DIM], gx[DIM] = {0.0, 0.0, 0.0}, gf = INFINITY;
    for (int d = 0; d < DIM; d++) vmax[d] = 0.2 * (HI[d] - LO[d]);
    for (int i = 0; i < n; i++) {
        for (int d = 0; d < DIM; d++) {
            pos[i][d] = px[i][d] = LO[d] + uniform(g) * (HI[d] - LO[d]);
            vel[i][d] = 0.0;
        }
        pf[i] = fitness(px[i], joints);
    }
    *evals += n;
    for (int i = 0; i < n; i++)
        if (pf[i] < gf) { gf = pf[i]; for (int d = 0; d < DIM; d++) gx[d] = px[i][d]; }
    for (int t = 1; t <= iterations; t++) {
        for (int i = 0; i < n; i++) {
            for (int d = 0; d < DIM; d++) {
                double r1 = uniform(g), r2 = uniform(g);
                double v = w * vel[i][d] + c1 * r1 * (px[i][d] - pos[i][d]) + c2 * r2 * (gx[d] - pos[i][d]);
                v = v < -vmax[d] ? -vmax[d] : (v > vmax[d] ? vmax[d] : v);
                double m = pos[i][d] + v, c = m < LO[d] ? LO[d] : (m > HI[d] ? HI[d] : m);
                vel[i][d] = c != m ? 0.0 : v;
                pos[i][d] = c;
            }
            double f = fitness(pos[i], joints);
            if (f < pf[i]) { pf[i] = f; for (int d = 0; d < DIM; d++) px[i][d] = pos[i][d]; }
        }
        *evals += n;
        for (int i = 0; i < n; i++)
            if (pf[i] < gf) { gf = pf[i]; for (int d = 0; d < DIM; d++) gx[d] = px[i][d]; }
    }
    return gf;
}

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv) {
    if (argc != 5 && argc != 6) {
        fprintf(stderr, "usage: %s ITERATIONS POPULATION RUNS SEED [gabc|abc|pso] < joints\n", argv[0]);
        return 2;
    }
    if (argc == 6) {
        const char *a = argv[5];
        if (a[0] == 'g' && a[1] == 'a') algorithm = GABC;
        else if (a[0] == 'a' && a[1] == 'b') algorithm = ABC;
        else if (a[0] == 'p' && a[1] == 's') algorithm = PSO;
        else { fprintf(stderr, "algorithm: gabc, abc or pso\n"); return 2; }
    }
    int iterations = atoi(argv[1]), sn = atoi(argv[2]), runs = atoi(argv[3]);
    uint64_t seed = strtoull(argv[4], NULL, 10);
    if (iterations < 1 || sn < 2 || sn > MAXPOP || runs < 1) {
        fprintf(stderr, "bad arguments\n");
        return 2;
    }
    int cap = 16, cases = 0;
    double *joints = malloc(sizeof(double) * DIM * cap);
    while (joints && scanf("%lf %lf %lf", &joints[DIM * cases], &joints[DIM * cases + 1],
                           &joints[DIM * cases + 2]) == 3) {
        if (++cases == cap) joints = realloc(joints, sizeof(double) * DIM * (cap *= 2));
    }
    if (!joints || cases == 0) {
        fprintf(stderr, "no joints read\n");
        return 2;
    }
    double *final = malloc(sizeof(double) * cases * runs);
    long evals = 0;
    struct timespec t0, t1, c0, c1;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (int c = 0; c < cases; c++)
        for (int r = 0; r < runs; r++) {
            pcg64 g;
            pcg64_seed(&g, seed, (uint64_t)c * 1000003ULL + (uint64_t)r);
            final[c * runs + r] = algorithm == PSO ? pso_run(iterations, sn, &g, &joints[DIM * c], &evals)
                                                   : gabc_run(iterations, sn, &g, &joints[DIM * c], &evals);
        }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
    double seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    double cpu = (double)(c1.tv_sec - c0.tv_sec) + 1e-9 * (double)(c1.tv_nsec - c0.tv_nsec);
    int n = cases * runs;
    qsort(final, n, sizeof(double), cmp_double);
    double median = n % 2 ? final[n / 2] : 0.5 * (final[n / 2 - 1] + final[n / 2]);
    printf("%ld %.9f %.6e %.6e %.9f\n", evals, seconds, median, final[n - 1], cpu);
    free(final);
    free(joints);
    return 0;
}
