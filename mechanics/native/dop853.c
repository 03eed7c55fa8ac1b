/* DOP853 — Dormand–Prince 8(5,3) with its 7th-order dense output — stepped in C.
 *
 * The algorithm is the one scipy's solve_ivp(method="DOP853") runs (Hairer's step-size control
 * with the blended 5th/3rd-order error estimate, the same initial-step guess, the same rules for
 * rejected steps), so for the same problem and tolerances it takes the same steps and RHS
 * evaluations; only the per-step overhead of Python is gone. The Butcher tableau (LAB_A, LAB_B,
 * LAB_C, LAB_E3, LAB_E5, LAB_D) is not written here: mechanics/native/__init__.py emits it from
 * scipy's own coefficient module into the prelude of this file before compiling, so the two can
 * never disagree.
 *
 * The right-hand side is a function pointer: a scene's generated C code, or a ctypes callback into
 * Python. The loop never hangs: a step budget, a wall-time deadline, and a floor on the step size
 * each end the run with a status; the samples written so far stay valid.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef int (*lab_rhs)(double t, const double *y, const double *p, double *dy);

typedef struct {
    long nfev;      /* right-hand-side evaluations, the initial-step probe included */
    long nsteps;    /* accepted steps */
    long nrejected; /* rejected step attempts */
    double t;       /* time reached */
    double t_bad;   /* the step that failed saw a non-finite value first here (NAN: never) */
    int n_out;      /* samples written to y_out, the initial state included */
    int rhs_code;   /* the nonzero code the right-hand side returned, if any */
} lab_result;

enum {
    LAB_OK = 0,
    LAB_STEP_BUDGET = 1,
    LAB_TOO_SMALL = 2,
    LAB_NONFINITE = 3,
    LAB_WALL_TIME = 4,
    LAB_RHS_ERROR = 5,
    LAB_NO_MEMORY = 6
};

#define SAFETY 0.9
#define MIN_FACTOR 0.2
#define MAX_FACTOR 10.0
#define ERROR_EXPONENT (-1.0 / 8.0) /* -1 / (error estimator order 7 + 1) */
#define N_STAGES 12

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int finite_all(const double *v, int n) {
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i])) return 0;
    return 1;
}

/* RMS norm of v / scale. */
static double rms(const double *v, const double *scale, int n) {
    double s = 0.0;
    for (int i = 0; i < n; i++) {
        double x = v[i] / scale[i];
        s += x * x;
    }
    return sqrt(s / n);
}

/* y_out = y + h * sum_{r < s} a[r] K[r] */
static void combine(double *out, const double *y, const double *K, const double *a, int s,
                    double h, int n) {
    for (int i = 0; i < n; i++) {
        double acc = 0.0;
        for (int r = 0; r < s; r++) acc += a[r] * K[r * n + i];
        out[i] = y[i] + h * acc;
    }
}

int lab_dop853(lab_rhs f, const double *p, int n, const double *y0, const double *t_out,
               int n_out, double *y_out, double rtol, double atol, long max_steps,
               double max_seconds, lab_result *r) {
    r->nfev = r->nsteps = r->nrejected = 0;
    r->t = t_out[0];
    r->t_bad = NAN;
    r->rhs_code = 0;
    memcpy(y_out, y0, sizeof(double) * n);
    r->n_out = 1;
    if (n_out <= 1) return LAB_OK;

    double *mem = malloc(sizeof(double) * n * (16 + 7 + 4));
    if (!mem) return LAB_NO_MEMORY;
    double *K = mem, *F = K + 16 * n, *y = F + 7 * n, *y_new = y + n, *tmp = y_new + n,
           *scale = tmp + n;
    int status = LAB_OK, code;
    double t = t_out[0], t_bound = t_out[n_out - 1];
    double deadline = now() + max_seconds;
    if (rtol < 100 * DBL_EPSILON) rtol = 100 * DBL_EPSILON;

#define CALL(tt, yy, out)                                                                      \
    do {                                                                                       \
        r->nfev++;                                                                             \
        if ((code = f((tt), (yy), p, (out))) != 0) {                                           \
            r->rhs_code = code;                                                                \
            status = LAB_RHS_ERROR;                                                            \
            goto done;                                                                         \
        }                                                                                      \
    } while (0)

    memcpy(y, y0, sizeof(double) * n);
    CALL(t, y, K);
    if (!finite_all(K, n)) {
        r->t_bad = t;
        status = LAB_NONFINITE;
        goto done;
    }

    /* Initial step: Hairer's guess from |y0|, |f0| and a probe Euler step (order 7 + 1). */
    double h_abs, interval = t_bound - t;
    {
        for (int i = 0; i < n; i++) scale[i] = atol + fabs(y[i]) * rtol;
        double d0 = rms(y, scale, n), d1 = rms(K, scale, n);
        double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
        if (h0 > interval) h0 = interval;
        for (int i = 0; i < n; i++) tmp[i] = y[i] + h0 * K[i];
        CALL(t + h0, tmp, F);
        for (int i = 0; i < n; i++) F[i] -= K[i];
        double d2 = rms(F, scale, n) / h0;
        double big = d1 > d2 ? d1 : d2;
        double h1 = (d1 <= 1e-15 && d2 <= 1e-15) ? fmax(1e-6, h0 * 1e-3)
                                                   : pow(0.01 / big, 1.0 / 8.0);
        h_abs = fmin(fmin(100 * h0, h1), interval);
        if (!isfinite(h_abs)) h_abs = 1e-6; /* a non-finite probe: let the step control sort it */
    }

    int k = 1; /* next output sample */
    while (k < n_out) {
        if (r->nsteps >= max_steps) {
            status = LAB_STEP_BUDGET;
            goto done;
        }
        if (now() > deadline) {
            status = LAB_WALL_TIME;
            goto done;
        }
        double min_step = 10 * fabs(nextafter(t, INFINITY) - t);
        if (h_abs < min_step) h_abs = min_step;
        int rejected = 0;
        double h, t_new;
        r->t_bad = NAN;
        for (;;) {
            if (h_abs < min_step) {
                status = isnan(r->t_bad) ? LAB_TOO_SMALL : LAB_NONFINITE;
                goto done;
            }
            t_new = t + h_abs;
            if (t_new > t_bound) t_new = t_bound;
            h = t_new - t;
            h_abs = fabs(h);
            int ok = 1;
            for (int s = 1; s < N_STAGES; s++) {
                combine(tmp, y, K, LAB_A[s], s, h, n);
                CALL(t + LAB_C[s] * h, tmp, K + s * n);
                if (!finite_all(K + s * n, n)) {
                    ok = 0;
                    if (isnan(r->t_bad)) r->t_bad = t + LAB_C[s] * h;
                    break;
                }
            }
            double err = NAN;
            if (ok) {
                combine(y_new, y, K, LAB_B, N_STAGES, h, n);
                CALL(t_new, y_new, K + N_STAGES * n);
                if (!finite_all(y_new, n) || !finite_all(K + N_STAGES * n, n)) {
                    ok = 0;
                    if (isnan(r->t_bad)) r->t_bad = t_new;
                }
            }
            if (ok) {
                double e5 = 0.0, e3 = 0.0;
                for (int i = 0; i < n; i++) {
                    double sc = atol + fmax(fabs(y[i]), fabs(y_new[i])) * rtol;
                    double a5 = 0.0, a3 = 0.0;
                    for (int s = 0; s <= N_STAGES; s++) {
                        a5 += LAB_E5[s] * K[s * n + i];
                        a3 += LAB_E3[s] * K[s * n + i];
                    }
                    a5 /= sc;
                    a3 /= sc;
                    e5 += a5 * a5;
                    e3 += a3 * a3;
                }
                err = (e5 == 0.0 && e3 == 0.0) ? 0.0 : h_abs * e5 / sqrt((e5 + 0.01 * e3) * n);
            }
            if (err < 1.0) { /* false for NAN: a non-finite attempt is a rejected step */
                double factor = err == 0.0 ? MAX_FACTOR
                                           : fmin(MAX_FACTOR, SAFETY * pow(err, ERROR_EXPONENT));
                if (rejected && factor > 1.0) factor = 1.0;
                h_abs *= factor;
                break;
            }
            double shrink = isnan(err) ? MIN_FACTOR : SAFETY * pow(err, ERROR_EXPONENT);
            h_abs *= fmax(MIN_FACTOR, shrink);
            rejected = 1;
            r->nrejected++;
        }
        r->nsteps++;

        if (t_out[k] <= t_new) {
            /* Dense output: three more stages, then F so that y(t_old + x h) is a polynomial. */
            for (int s = N_STAGES + 1; s < 16; s++) {
                combine(tmp, y, K, LAB_A[s], s, h, n);
                CALL(t + LAB_C[s] * h, tmp, K + s * n);
            }
            for (int i = 0; i < n; i++) {
                double dy = y_new[i] - y[i];
                F[i] = dy;
                F[n + i] = h * K[i] - dy;
                F[2 * n + i] = 2 * dy - h * (K[N_STAGES * n + i] + K[i]);
                for (int j = 0; j < 4; j++) {
                    double acc = 0.0;
                    for (int s = 0; s < 16; s++) acc += LAB_D[j][s] * K[s * n + i];
                    F[(3 + j) * n + i] = h * acc;
                }
            }
            while (k < n_out && t_out[k] <= t_new) {
                double *out = y_out + (long)k * n;
                if (t_out[k] == t_new) {
                    memcpy(out, y_new, sizeof(double) * n);
                } else {
                    double x = (t_out[k] - t) / h;
                    for (int i = 0; i < n; i++) {
                        double v = 0.0;
                        for (int j = 6; j >= 0; j--) {
                            v += F[j * n + i];
                            v *= (j % 2 == 0) ? x : 1.0 - x;
                        }
                        out[i] = y[i] + v;
                    }
                }
                if (!finite_all(out, n)) {
                    r->t_bad = t_out[k];
                    status = LAB_NONFINITE;
                    goto done;
                }
                k++;
                r->n_out = k;
            }
        }
        t = t_new;
        r->t = t;
        memcpy(y, y_new, sizeof(double) * n);
        memcpy(K, K + N_STAGES * n, sizeof(double) * n); /* first same as last */
    }
#undef CALL
done:
    free(mem);
    return status;
}
