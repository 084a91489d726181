/* The laws in step form: fvd_bridge's laws for one member, sample by sample.
 * Part of the damper FMU's physics (hand-kept); model.c compiles it into its
 * translation unit (#include "laws.c"), so every function stays static.
 * Units: kN, mm, s.
 *
 * Mirrors, function for function and with the same names, the Python
 * reference step forms; each equation's source is in the docstring of its
 * Python twin (module named above each group):
 *   fvd_bridge/laws/fastmath.py   log1p_ratio, relax, powsign (see below)
 *   fvd_bridge/laws/steps.py      split_travel ... maxwell_force
 *   fvd_bridge/laws/trbdf2.py     law7_constants ... maxwell_solve
 *   fvd_bridge/laws/oil.py        relief_velocity, oil_solve, oil_step (law 10)
 *   fvd_bridge/laws/scalar.py     law_constants, new_state, advance, force
 *                                 (history's loop body is law_sample + force,
 *                                 effects.c)
 * A Python function that returns a tuple writes through pointers here; a
 * private Python helper _name is name_ here.  The C library's exp, log,
 * log1p, expm1, atanh, pow and tanh stand for fastmath.py's vexp, vlog,
 * log1p_ratio, relax and coarse_log (numba cannot vectorize libm; C has no
 * such need), so the FMU agrees with the Python model to rounding and the
 * Newton tolerance (1e-10 in ln|z|), not bit for bit.
 *
 * A law is its number `code` and its parameters p (the registry's order,
 * fvd_bridge.laws.LAWS[code].parameters); law_parameter_problem states the
 * parameter values the equations need.
 */
#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <string.h>

#include "damper.h"

/* ------------------------------------------------------- fvd_bridge/laws/fastmath.py */
/* vexp saturates at EXP_MAX; the C library's exp overflows above ~709.78 */
#define EXP_MAX 709.0
#define LN2 0.69314718055994530942
#define COARSE_LOG_ERROR 0.01

/* ln(1 + y)/y for y > -1 (1 at y = 0), without cancellation near 0 */
static double log1p_ratio(double y) {
    return y != 0.0 ? log1p(y) / y : 1.0;
}

/* phi(x) = (1 - e^-x)/x, phi(0) = 1 (the exact integrating factor) */
static double relax(double x) {
    return x != 0.0 ? -expm1(-x) / x : 1.0;
}

/* sign(x) |x|^p (0 at x = 0) */
static double powsign(double x, double p) {
    return x != 0.0 ? copysign(pow(fabs(x), p), x) : 0.0;
}

/* ---------------------------------------------------------- fvd_bridge/laws/steps.py */
static void split_travel(double v0, double v1, double h, double *u1, double *u2) {
    if (v0 * v1 >= 0.0) {
        *u1 = 0.5 * (v0 + v1) * h;
        *u2 = 0.0;
        return;
    }
    const double tau = h * v0 / (v0 - v1);
    *u1 = 0.5 * v0 * tau;
    *u2 = 0.5 * v1 * (h - tau);
}

static double bouc_wen_step(double z, double u, double A, double beta, double gamma) {
    const double sgn = u >= 0.0 ? 1.0 : -1.0;
    const double w = sgn * z, s = fabs(u);
    const double k_un = beta - gamma, k_lo = beta + gamma;
    const bool unloading = w < 0.0;
    const double y = -k_un * w / A;
    double s0 = -w / A * log1p_ratio(y);
    s0 = !unloading ? 0.0 : (y > -1.0 ? s0 : 1e300);  /* 1e300: w = 0 is never reached */
    const double w_un = w + (A - k_un * w) * s * relax(k_un * s);
    const double w1 = unloading ? 0.0 : w;
    const double s2 = fmax(s - s0, 0.0);
    const double w_lo = w1 + (A - k_lo * w1) * s2 * relax(k_lo * s2);
    return sgn * ((unloading && s < s0) ? w_un : w_lo);
}

static double lugre_step(double z, double u, double a) {
    const double sgn = u >= 0.0 ? 1.0 : -1.0;
    const double s = fabs(u);
    return z + (sgn - a * z) * s * relax(a * s);
}

static double slip_step(double z, double u, double k) {
    return fmin(fmax(z + k * u, -1.0), 1.0);
}

/* k = (C, alpha, K1, K2, K, beta) */
static void algebraic_form(int code, const double *p, double *k) {
    double C = p[0], alpha = 1.0, K1 = 0.0, K2 = 0.0, K = 0.0, beta = 1.0;
    if (code == 2) {
        alpha = p[1];
    } else if (code == 3) {
        alpha = p[1]; K1 = p[2];
    } else if (code == 4) {
        alpha = p[1]; K1 = p[2]; K2 = p[3];
    } else if (code == 5) {
        alpha = p[1]; K = p[2]; beta = p[3];
    }
    k[0] = C; k[1] = alpha; k[2] = K1; k[3] = K2; k[4] = K; k[5] = beta;
}

static double power_term(double c, double sign_x, double log_abs_x, double e) {
    return c * sign_x * exp(e * log_abs_x);
}

static double algebraic_force(double C, double alpha, double K1, double K2, double K, double beta, double d,
                              double sign_v, double log_v, double sign_d, double log_d) {
    const double f = power_term(C, sign_v, log_v, alpha) + K1 * d + K2 * d * d;
    return K != 0.0 ? f + power_term(K, sign_d, log_d, beta) : f;
}

static void sign_log(double x, double *sign, double *log_abs) {
    const double ax = fabs(x);
    *sign = x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0);
    *log_abs = ax > 0.0 ? log(ax) : -1e300;
}

/* k = (a, b, C, A, beta, gamma) */
static void bouc_wen_constants(double C, double K, double alpha, double A, double beta, double gamma, double *k) {
    k[0] = alpha * K; k[1] = (1.0 - alpha) * K; k[2] = C; k[3] = A; k[4] = beta; k[5] = gamma;
}

/* out = (C, K, alpha, A, beta, gamma) */
static void law6_bouc_wen(double C, double K, double alpha, double beta, double *out) {
    out[0] = C; out[1] = K; out[2] = alpha; out[3] = 1.0; out[4] = beta; out[5] = beta;
}

/* k = (0, mu N, C, K/(mu N)) */
static void law8_constants(double C, double K, double mu, double N, double *k) {
    const double mu_N = mu * N;
    k[0] = 0.0; k[1] = mu_N; k[2] = C; k[3] = mu_N > 0.0 ? K / mu_N : 0.0;
}

/* k = (0, beta, C, alpha) */
static void law9_constants(double C, double alpha, double beta, double *k) {
    k[0] = 0.0; k[1] = beta; k[2] = C; k[3] = alpha;
}

static double linear_force(double a, double b, double C, double d, double z, double v) {
    return a * d + b * z + C * v;
}

static double maxwell_log_rate(double C, double alpha, double K) {
    const double ln_ratio = log(fmax(K, 1e-300)) - log(fmax(C, 1e-300));
    return fmin(fmax(ln_ratio / alpha, -700.0), 700.0);
}

static double maxwell_force(double sign_z, double lam, double ln_K, double beta) {
    const double f = copysign(exp(fmin(ln_K + beta * lam, EXP_MAX)), sign_z);
    return sign_z != 0.0 ? f : 0.0;
}

/* --------------------------------------------------------- fvd_bridge/laws/trbdf2.py */
#define TRBDF2_GAMMA (2.0 - 1.41421356237309504880)
#define LAM_MIN (-700.0)
#define R_MIN 1e-300
#define DEN_MIN 1e-280  /* a Newton step's denominator below this: at rest, no step */
#define NEWTON_TOL 1e-10
#define NEWTON_MAXIT 50

/* k = (ln c, p, 1/p, ln K, beta) */
static void law7_constants(double C, double alpha, double K, double beta, double h, double *k) {
    const double p = beta / alpha;
    k[0] = log(0.5 * TRBDF2_GAMMA * h) + maxwell_log_rate(C, alpha, K);
    k[1] = p; k[2] = 1.0 / p; k[3] = log(fmax(K, 1e-300)); k[4] = beta;
}

static double maxwell_tr_rhs(double z, double c_phi, double v0, double v1, double h) {
    const double g = TRBDF2_GAMMA;
    return z + 0.5 * g * h * (2.0 * v0 + g * (v1 - v0)) - c_phi;
}

static double maxwell_bdf2_rhs(double z_gamma, double z, double v1, double h) {
    const double g = TRBDF2_GAMMA;
    return (z_gamma - (1.0 - g) * (1.0 - g) * z) / (g * (2.0 - g)) + 0.5 * g * h * v1;
}

/* exact logs in place of coarse_log (the bracket keeps its margin) */
static void maxwell_start(double r, double R_prev, double lam, double lam1, double lam2, double ln_r_prev,
                          double ln_c, double inv_p, double *lam0, double *ln_r_out, double *R_out) {
    const double R = fmax(fabs(r), R_MIN);
    const double ln_r = log(R);
    const double t = (R - R_prev) / (R + R_prev);
    const double dl = fabs(t) < 0.1 ? 2.0 * atanh(t) : ln_r - ln_r_prev;
    const double upper = fmin(ln_r, (ln_r - ln_c) * inv_p) + COARSE_LOG_ERROR;
    const double lower = fmin(ln_r - LN2, (ln_r - LN2 - ln_c) * inv_p) - COARSE_LOG_ERROR;
    *lam0 = fmax(fmin(fmax(lam + dl * (lam1 + lam2 * dl), lower), upper), LAM_MIN);
    *ln_r_out = ln_r;
    *R_out = R;
}

static void maxwell_newton(double lam, double R, double ln_c, double p,
                           double *new_lam, double *e1_out, double *e2_out, double *inv_g1, bool *converged) {
    const double e1 = exp(fmin(lam, EXP_MAX));
    const double e2 = exp(fmin(ln_c + p * lam, EXP_MAX));
    const double s = e1 + e2;
    const double g1 = e1 + p * e2;
    const double den = (s + R) * g1;
    const double inv = den > DEN_MIN ? 1.0 / den : 0.0;  /* at rest the terms underflow: stay, slopes 0 */
    const double nl = fmax(lam - 2.0 * s * (s - R) * inv, LAM_MIN);
    const double d = fabs(nl - lam);
    *converged = e1 * e2 * (p - 1.0) * (p - 1.0) * d * d <= (2.0 * NEWTON_TOL - d * d * d / 6.0) * s * g1;
    *new_lam = nl;
    *e1_out = e1;
    *e2_out = e2;
    *inv_g1 = (s + R) * inv;
}

static void maxwell_end(double r, double e1, double e2, double inv_g1, double dlam, double p,
                        double *x, double *lam1, double *lam2) {
    const double s = e1 + e2;
    *lam1 = s * inv_g1;
    *lam2 = -0.5 * (e1 * inv_g1) * (e2 * inv_g1) * (p - 1.0) * (p - 1.0) * (s * inv_g1);  /* bounded ratios: no overflow at rest */
    *x = copysign(e1 * (1.0 + dlam * (1.0 + 0.5 * dlam)), r);
}

static double maxwell_solve(double r, double ln_c, double p) {
    const double R = fmax(fabs(r), R_MIN);
    const double ln_r = log(R);
    double lam = fmax(fmin(ln_r, (ln_r - ln_c) / p), LAM_MIN);
    double e1 = 0.0, e2 = 0.0, inv_g1 = 1.0, dlam = 0.0, nl, x, lam1, lam2;
    bool done;
    for (int i = 0; i < NEWTON_MAXIT; i++) {
        maxwell_newton(lam, R, ln_c, p, &nl, &e1, &e2, &inv_g1, &done);
        dlam = nl - lam;
        lam = nl;
        if (done) break;
    }
    if (r == 0.0) return 0.0;
    maxwell_end(r, e1, e2, inv_g1, dlam, p, &x, &lam1, &lam2);
    return x;
}

/* ------------------------------------------------------------ fvd_bridge/laws/oil.py */
/* the dashpot velocity v_d [mm/s] at the force F [kN] */
static double relief_velocity(double F, double C, double Fr, double p) {
    if (fabs(F) <= Fr) return F / C;
    return copysign(Fr / C + (fabs(F) - Fr) / (p * C), F);
}

/* F with F + c v_d(F) = R, c > 0 */
static double oil_solve(double R, double c, double C, double Fr, double p) {
    const double F = R / (1.0 + c / C);
    if (fabs(F) <= Fr) return F;
    const double pC = p * C;
    return copysign(Fr + (fabs(R) - Fr * (1.0 + c / C)) * pC / (pC + c), R);
}

/* the spring force [kN] after a sub-step h [s] from F, the velocity linear from va to vb (TR-BDF2) */
static double oil_step(double K, double C, double Fr, double p, double F, double va, double vb, double h) {
    const double g = TRBDF2_GAMMA;
    const double c_g = 1.0 / (g * (2.0 - g));
    const double c_0 = (1.0 - g) * (1.0 - g) * c_g;
    const double c_h = (1.0 - g) / (2.0 - g) * h;
    const double psi_g = g * h * (va + 0.5 * g * (vb - va));
    const double psi_h = 0.5 * h * (va + vb);
    const double c_1 = 0.5 * K * g * h;
    const double F_g = oil_solve(F + K * psi_g - c_1 * relief_velocity(F, C, Fr, p), c_1, C, Fr, p);
    return oil_solve(c_g * F_g - c_0 * F + K * (psi_h - c_g * psi_g), K * c_h, C, Fr, p);
}

/* --------------------------------------------------------- fvd_bridge/laws/scalar.py */
enum { Z, C_PHI, RHS, ABS_R, LAM, LAM1, LAM2, LN_R, E1, E2, INV_G1, DLAM, DONE };  /* law 7 state */
enum { LN_C, P, INV_P, LN_K, BETA };  /* law 7 constants */
#define STEP 3  /* laws 6, 8, 9: first constant of the step (after a, b, C) */

/* k: 6 constants (laws 1-6), 4 (laws 8, 9, 10) or 5 (law 7) */
static void law_constants(int code, const double *p, double h, double *k) {
    double b[6];
    if (code <= 5) {
        algebraic_form(code, p, k);
    } else if (code == 6) {
        law6_bouc_wen(p[0], p[1], p[2], p[3], b);
        bouc_wen_constants(b[0], b[1], b[2], b[3], b[4], b[5], k);
    } else if (code == 7) {
        law7_constants(p[0], p[1], p[2], p[3], h, k);
    } else if (code == 8) {
        law8_constants(p[0], p[1], p[2], p[3], k);
    } else if (code == 10) {
        k[0] = p[0]; k[1] = p[1]; k[2] = p[2]; k[3] = p[3];
    } else {
        law9_constants(p[0], p[1], p[2], k);
    }
}

static void new_state(int code, double *s) {
    memset(s, 0, N_LAW_STATE * sizeof(double));
    if (code == 7) {
        s[LAM] = LAM_MIN; s[LAM1] = 1.0; s[LN_R] = LAM_MIN; s[E1] = exp(LAM_MIN); s[INV_G1] = exp(-LAM_MIN);
    }
}

static double travel_step_(int code, const double *k, double z, double u) {
    if (code == 6) return bouc_wen_step(z, u, k[STEP], k[STEP + 1], k[STEP + 2]);
    if (code == 8) return slip_step(z, u, k[STEP]);
    return lugre_step(z, u, k[STEP]);
}

static void maxwell_solve_(const double *k, double *s, double r) {
    double lam0, R, lam, e1, e2, inv_g1;
    bool done;
    maxwell_start(r, s[ABS_R], s[LAM], s[LAM1], s[LAM2], s[LN_R], k[LN_C], k[INV_P], &lam0, &s[LN_R], &R);
    maxwell_newton(lam0, R, k[LN_C], k[P], &lam, &e1, &e2, &inv_g1, &done);
    s[E1] = e1; s[E2] = e2; s[INV_G1] = inv_g1;
    s[RHS] = r; s[ABS_R] = R; s[LAM] = lam; s[DLAM] = lam - lam0; s[DONE] = done;
    for (int i = 0; i < NEWTON_MAXIT; i++) {
        if (s[DONE] != 0.0) return;
        maxwell_newton(s[LAM], s[ABS_R], k[LN_C], k[P], &lam, &e1, &e2, &inv_g1, &done);
        s[E1] = e1; s[E2] = e2; s[INV_G1] = inv_g1;
        s[DLAM] = lam - s[LAM]; s[LAM] = lam; s[DONE] = done;
    }
}

static double maxwell_root_(const double *k, double *s) {
    double x;
    maxwell_end(s[RHS], s[E1], s[E2], s[INV_G1], s[DLAM], k[P], &x, &s[LAM1], &s[LAM2]);
    return x;
}

static void advance(int code, const double *k, double *s, double va, double vb, double h) {
    if (code == 7) {
        for (int stage = 0; stage < 2; stage++) {  /* trapezoidal to t + gamma h, then BDF2 to t + h */
            const double x = maxwell_root_(k, s);  /* root of the previous solve */
            if (stage == 0) {  /* that was z at the start of the step */
                s[Z] = x;
                s[C_PHI] = s[RHS] - x;
            }
            const double r = stage == 0 ? maxwell_tr_rhs(s[Z], s[C_PHI], va, vb, h)
                                        : maxwell_bdf2_rhs(x, s[Z], vb, h);
            maxwell_solve_(k, s, r);
        }
    } else if (code == 10) {
        s[Z] = oil_step(k[0], k[1], k[2], k[3], s[Z], va, vb, h);
    } else if (code >= 6) {
        double u[2];
        split_travel(va, vb, h, &u[0], &u[1]);
        for (int i = 0; i < 2; i++) {
            if (u[i] != 0.0) s[Z] = travel_step_(code, k, s[Z], u[i]);
        }
    }
}

static double force(int code, const double *k, const double *s, double d, double v) {
    if (code <= 5) {
        double sign_v, log_v, sign_d, log_d;
        sign_log(v, &sign_v, &log_v);
        sign_log(d, &sign_d, &log_d);
        return algebraic_force(k[0], k[1], k[2], k[3], k[4], k[5], d, sign_v, log_v, sign_d, log_d);
    }
    if (code == 7) return maxwell_force(s[RHS], s[LAM], k[LN_K], k[BETA]);
    if (code == 10) return s[Z];
    return linear_force(k[0], k[1], k[2], d, s[Z], v);
}

/* laws/differential.py: velocities at the ends of sub-step j of m */
static void sub_velocities_(double v0, double v1, int j, int m, double *va, double *vb) {
    *va = v0 + (v1 - v0) * j / m;
    *vb = v0 + (v1 - v0) * (j + 1) / m;
}

/* ------------------------------------------------------------- parameter rules */
/* The first of a law's parameters p whose value its equations cannot take:
 * its index in p into *index and the rule it breaks; NULL when there is none. */
static const char *law_parameter_problem(int code, const double *p, int *index) {
#define RULE(cond, i, rule) do { if (!(cond)) { *index = (i); return (rule); } } while (0)
    switch (code) {
        case 2: case 3: case 4:
            RULE(p[1] >= 0.0, 1, "the damping exponent must be >= 0");
            break;
        case 5:
            RULE(p[1] >= 0.0, 1, "the damping exponent must be >= 0");
            RULE(p[3] >= 0.0, 3, "the spring exponent must be >= 0");
            break;
        case 6:
            RULE(p[3] >= 0.0, 3, "the hysteresis shape must be >= 0 1/mm");
            break;
        case 7:
            RULE(p[0] > 0.0, 0, "the dashpot coefficient must be > 0");
            RULE(p[1] > 0.0, 1, "the dashpot exponent must be > 0");
            RULE(p[2] > 0.0, 2, "the spring coefficient must be > 0");
            RULE(p[3] > 0.0, 3, "the spring exponent must be > 0");
            break;
        case 8:
            RULE(p[1] >= 0.0, 1, "the slip stiffness must be >= 0 kN/mm");
            RULE(p[2] * p[3] >= 0.0, 3, "the slip force mu N must be >= 0 kN");
            break;
        case 9:
            RULE(p[1] >= 0.0, 1, "the inverse saturation travel must be >= 0 1/mm");
            break;
        case 10:
            RULE(p[0] >= 0.0, 0, "the spring stiffness must be >= 0 kN/mm");
            RULE(p[1] > 0.0, 1, "the damping coefficient must be > 0");
            RULE(p[2] >= 0.0, 2, "the relief force must be >= 0 kN");
            RULE(p[3] > 0.0, 3, "the post-relief damping ratio must be > 0");
            break;
        default:
            break;
    }
    return NULL;
#undef RULE
}
