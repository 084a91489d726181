/* The damper: fvd_bridge's nine laws and seven built-in effects for one
 * member, sample by sample, as an FMI 3.0 co-simulation model.  Units: kN,
 * mm, s, mass kg.
 *
 * The physics mirrors, function for function and with the same names, the
 * Python reference step forms; each equation's source is in the docstring
 * of its Python twin (module named above each group):
 *   fvd_bridge/laws/steps.py      split_travel ... maxwell_force
 *   fvd_bridge/laws/trbdf2.py     law7_constants ... maxwell_solve
 *   fvd_bridge/laws/scalar.py     law_constants, new_state, advance, force
 *                                 (history's loop body is law_sample + force)
 *   fvd_bridge/effects/steps.py   asymmetry_factor ... series_sample
 *   fvd_bridge/effects/scalar.py  law_sample, model_history (its loop body:
 *                                 model_history_sample, k = 0 at initialization,
 *                                 k > 0 in each fmi3DoStep)
 * A Python function that returns a tuple writes through pointers here; a
 * private Python helper _name is name_ here.  The C library's exp, log,
 * log1p, expm1, atanh, pow and tanh stand for fastmath.py's vexp, vlog,
 * log1p_ratio, relax and coarse_log (numba cannot vectorize libm; C has no
 * such need), so the FMU agrees with the Python model to rounding and the
 * Newton tolerance (1e-10 in ln|z|), not bit for bit.
 *
 * Co-simulation convention: before fmi3DoStep(t, h) the master sets the
 * pin's displacement d at the END of the step, d(t + h) (and v, a when
 * use_velocity_input, use_acceleration_input); the step then integrates
 * over [t, t + h] in n = ceil(h / h_max) equal sub-steps, as the Python
 * model does over one sample step with `substeps = n`, and F, z, E are the
 * values at t + h.  (Start-of-step values delay the force by one step: OF
 * 0.012-0.022 against the Python model on the golden records, 4e-5 to 3e-4
 * with end-of-step values.)  Without those inputs v and a are derived from
 * the samples of d (backward_derivative: second-order, from rest at
 * initialization).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model.h"

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
    const double inv = 1.0 / ((s + R) * g1);
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
    *lam2 = -0.5 * e1 * e2 * (p - 1.0) * (p - 1.0) * s * inv_g1 * inv_g1 * inv_g1;
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

/* --------------------------------------------------------- fvd_bridge/laws/scalar.py */
enum { Z, C_PHI, RHS, ABS_R, LAM, LAM1, LAM2, LN_R, E1, E2, INV_G1, DLAM, DONE };  /* law 7 state */
enum { LN_C, P, INV_P, LN_K, BETA };  /* law 7 constants */
#define STEP 3  /* laws 6, 8, 9: first constant of the step (after a, b, C) */

/* k: 6 constants (laws 1-6), 4 (laws 8, 9) or 5 (law 7) */
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
    return linear_force(k[0], k[1], k[2], d, s[Z], v);
}

/* laws/differential.py: velocities at the ends of sub-step j of m */
static void sub_velocities_(double v0, double v1, int j, int m, double *va, double *vb) {
    *va = v0 + (v1 - v0) * j / m;
    *vb = v0 + (v1 - v0) * (j + 1) / m;
}

/* ------------------------------------------------------- fvd_bridge/effects/steps.py */
#define FRICTION_V_F 1.0
#define J_TO_MJ 1e-6
#define U_MAX 1e12
#define ALPHA_MIN 1e-3
#define KS_RIGID 1e6  /* effects/catalog.py */
#define KS_RIGID_FROM (KS_RIGID * (1.0 - 1e-12))

static double asymmetry_factor(double F, double r) {
    return F > 0.0 ? 1.0 + r : (F < 0.0 ? 1.0 - r : 1.0);
}

static double friction_term(double Ff, double u) {
    return Ff * tanh(u / FRICTION_V_F);
}

static double heat_factor(double theta, double W0) {
    return 1.0 / (1.0 + theta * W0);
}

static double parallel_spring(double Kp, double F0, double x) {
    return Kp * x + F0;
}

static double inertia_term(double m, double xa) {
    return m * 1e-6 * xa;
}

static double heat_energy(double W0, double p0, double p1, double dt) {
    return W0 + 0.5 * dt * (p0 + p1) * J_TO_MJ;
}

static void algebraic_law(int code, double x, double u, const double *p, double *F, double *dS) {
    double k[6], sign_u, log_u, sign_x, log_x;
    algebraic_form(code, p, k);
    const double C = k[0], alpha = k[1], K1 = k[2], K2 = k[3], K = k[4], beta = k[5];
    sign_log(u, &sign_u, &log_u);
    sign_log(x, &sign_x, &log_x);
    *F = algebraic_force(C, alpha, K1, K2, K, beta, x, sign_u, log_u, sign_x, log_x);
    *dS = K1 + 2.0 * K2 * x + (x != 0.0 ? beta * power_term(K, 1.0, log_x, beta - 1.0) : 0.0);
}

static void law6_constants(const double *p, double *k) {
    double b[6];
    law6_bouc_wen(p[0], p[1], p[2], p[3], b);
    bouc_wen_constants(b[0], b[1], b[2], b[3], b[4], b[5], k);
}

static double hysteretic_state(int code, double z0, double u, const double *p, double zb, double hz) {
    double k[6];
    if (code == 6) {
        law6_constants(p, k);
        return bouc_wen_step(z0, u, k[3], k[4], k[5]);
    }
    if (code == 8) {
        law8_constants(p[0], p[1], p[2], p[3], k);
        return slip_step(z0, u, k[3]);
    }
    if (code == 9) {
        law9_constants(p[0], p[1], p[2], k);
        return lugre_step(z0, u, k[3]);
    }
    return maxwell_solve(zb + u, log(hz) + maxwell_log_rate(p[0], p[1], p[2]), p[3] / p[1]);
}

static double law7_rate(double z, const double *p) {
    if (z == 0.0) return 0.0;
    return copysign(exp(maxwell_log_rate(p[0], p[1], p[2]) + p[3] / p[1] * log(fabs(z))), z);
}

static double hysteretic_force(int code, double x, double z, double u, const double *p) {
    double k[6];
    if (code == 6) {
        law6_constants(p, k);
    } else if (code == 8) {
        law8_constants(p[0], p[1], p[2], p[3], k);
    } else if (code == 9) {
        law9_constants(p[0], p[1], p[2], k);
    } else {  /* law 7 */
        return maxwell_force(z, z != 0.0 ? log(fabs(z)) : LAM_MIN, log(fmax(p[2], 1e-300)), p[3]);
    }
    return linear_force(k[0], k[1], k[2], x, z, u);
}

static double law_exponent(int code, const double *p) {
    if (2 <= code && code <= 5) return fmin(fmax(p[1], ALPHA_MIN), 1.0);
    return 1.0;
}

static void q_to_u(double q, double a, double *u, double *dudq) {
    if (q == 0.0) {
        *u = 0.0;
        *dudq = a == 1.0 ? 1.0 : 0.0;
        return;
    }
    if (a == 1.0) {
        *u = q;
        *dudq = 1.0;
        return;
    }
    const double lu = log(fabs(q)) / a;
    if (lu > log(U_MAX)) {
        *u = copysign(U_MAX, q);
        *dudq = 0.0;
        return;
    }
    *u = copysign(exp(lu), q);
    *dudq = fabs(*u) / (a * fabs(q));
}

static void element_force(int code, const double *p, double x, double x0, double u, double z0, double zb,
                          double hz, double r, double hf, double Ff,
                          double *F_int, double *F_o, double *z, double *dfric, double *dFo_dx) {
    double Fl, dFdx;
    *z = z0;
    if (code <= 5) {
        algebraic_law(code, x, u, p, &Fl, &dFdx);
    } else {
        *z = hysteretic_state(code, z0, x - x0, p, zb, hz);
        Fl = hysteretic_force(code, x, *z, u, p);
        dFdx = 0.0;
    }
    const double A = asymmetry_factor(Fl, r);
    const double Fo = hf * A * Fl;
    const double fr = Ff != 0.0 ? friction_term(Ff, u) : 0.0;
    const double th = Ff != 0.0 ? fr / Ff : 0.0;
    *F_int = Fo + fr;
    *F_o = Fo;
    *dfric = Ff / FRICTION_V_F * (1.0 - th * th);
    *dFo_dx = hf * A * dFdx;
}

static double hermite_travel(double s, double h, double v0, double v1, double a0, double a1) {
    const double s2 = s * s, s3 = s2 * s, s4 = s3 * s;
    return h * ((0.5 * s4 - s3 + s) * v0 + (0.25 * s4 - 2.0 * s3 / 3.0 + 0.5 * s2) * h * a0
                + (-0.5 * s4 + s3) * v1 + (0.25 * s4 - s3 / 3.0) * h * a1);
}

static double gap_half(double g) {
    return 0.5 * fmax(g, 0.0);
}

static double dead_zone(double w, double half, double *slope) {
    if (half == 0.0) {
        *slope = 1.0;
        return w;
    }
    if (w > half) {
        *slope = 1.0;
        return w - half;
    }
    if (w < -half) {
        *slope = 1.0;
        return w + half;
    }
    *slope = 0.0;
    return 0.0;
}

static double gap_side(double w, double half) {
    if (w >= half) return 1.0;
    if (w <= -half) return -1.0;
    return 0.0;
}

static double linear_travel(double f, double dt, double v0, double v1) {
    return dt * f * (v0 + 0.5 * (v1 - v0) * f);
}

/* series_residual's tuple (R, dR/dq, u, w, F_o, z) */
typedef struct { double R, dR, u, w, Fo, z; } Residual;

static Residual series_residual(double q, double a, int code, const double *p, double y, double wb, double hth,
                                double x0, double z0, double zb, double Ks, double half, double r, double hf,
                                double Ff, double Kp, double F0) {
    Residual res;
    double dudq, Fi, Fo, z, dfric, dFdx, ds;
    q_to_u(q, a, &res.u, &dudq);
    res.w = wb - hth * res.u;
    const double x = y - res.w;
    element_force(code, p, x, x0, res.u, z0, zb, hth, r, hf, Ff, &Fi, &Fo, &z, &dfric, &dFdx);
    if (Kp != 0.0 || F0 != 0.0) Fi = Fi + parallel_spring(Kp, F0, x);
    const double s = dead_zone(res.w, half, &ds);
    const double kd = Ks * ds;
    if (code <= 5 && code != 1) {
        res.dR = hf * asymmetry_factor(Fo, r) * p[0] + (dFdx * hth + dfric + (Kp + kd) * hth) * dudq;
    } else if (code == 1) {
        res.dR = (hf * asymmetry_factor(Fo, r) * p[0] + dfric + (Kp + kd) * hth) * dudq;
    } else {
        res.dR = 0.0;  /* estimated by the solver from a secant */
    }
    res.R = Fi - Ks * s;
    res.Fo = Fo;
    res.z = z;
    return res;
}

static Residual series_step(double q_guess, double a, int code, const double *p, double y, double wb, double hth,
                            double x0, double z0, double zb, double Ks, double half, double r, double hf, double Ff,
                            double Kp, double F0) {
#define RESIDUAL(qq) series_residual(qq, a, code, p, y, wb, hth, x0, z0, zb, Ks, half, r, hf, Ff, Kp, F0)
    double lo = -INFINITY, hi = INFINITY;
    double q = q_guess;
    Residual res = RESIDUAL(q);
    double dR = res.dR;
    double q_prev = NAN, R_prev = NAN;
    double scale = 0.5 * fabs(q) + 1e-3;
    for (int it = 0; it < 200; it++) {
        const double R = res.R;
        if (R == 0.0 || !isfinite(R)) break;
        if (R < 0.0) {
            lo = q;
        } else {
            hi = q;
        }
        if (code > 5) {
            if (q_prev == q_prev && q_prev != q && R != R_prev) {
                dR = (R - R_prev) / (q - q_prev);
            } else {
                const double dq = 1e-7 * (1.0 + fabs(q));
                dR = (RESIDUAL(q + dq).R - R) / dq;
            }
        }
        const double step = dR > 0.0 ? R / dR : NAN;
        if (fabs(step) <= 1e-9 * (1.0 + fabs(q))) break;
        double qn = q - step;
        if (isinf(lo) || isinf(hi)) {
            /* open bracket: go downhill, at most `scale` (growing) at a time */
            const double down = R < 0.0 ? 1.0 : -1.0;
            if (!(qn == qn && (qn - q) * down > 0.0 && fabs(qn - q) <= scale)) {
                qn = q + down * scale;
                scale *= 4.0;
            }
        } else if (!(lo < qn && qn < hi)) {
            qn = 0.5 * (lo + hi);
            if (hi - lo <= 1e-14 * (1.0 + fabs(qn))) {
                q = qn;
                res = RESIDUAL(q);
                break;
            }
        }
        q_prev = q;
        R_prev = R;
        q = qn;
        res = RESIDUAL(q);
        dR = res.dR;
    }
    return res;
#undef RESIDUAL
}

/* series_stage's tuple (u, w, F_o, z, F) as a Residual: R holds F */
static Residual series_stage(double q_guess, double a, int code, const double *p, double y, double wb, double hth,
                             double x0, double z0, double zb, double Ks, double half, double r, double hf, double Ff,
                             double Kp, double F0) {
    Residual res;
    double ds;
    if (!isinf(Ks)) {
        res = series_step(q_guess, a, code, p, y, wb, hth, x0, z0, zb, Ks, half, r, hf, Ff, Kp, F0);
        res.R = Ks * dead_zone(res.w, half, &ds);
        return res;
    }
    const double first = wb >= 0.0 ? 1.0 : -1.0;  /* the side the connection leans to first */
    for (int i = 0; i < 2; i++) {
        const double side = i == 0 ? first : -first;
        const double u = (wb - side * half) / hth;
        const double q = a != 1.0 ? powsign(u, a) : u;
        res = series_residual(q, a, code, p, y, wb, hth, x0, z0, zb, 0.0, half, r, hf, Ff, Kp, F0);
        if (side * res.R > 0.0) {
            res.u = u;
            res.w = side * half;
            return res;
        }
    }
    res = series_step(q_guess, a, code, p, y, wb, hth, x0, z0, zb, 0.0, half, r, hf, Ff, Kp, F0);
    res.w = fmin(fmax(res.w, -half), half);
    res.R = 0.0;
    return res;
}

enum { SW, SU, SZ, SW0, SPW, SXL, SQ, SDQ };  /* series_sample's state (w, u, z, W0, pw, x_o, q, dq) */

static void series_rest(double x0, double *state) {
    memset(state, 0, N_SPRING * sizeof(double));
    state[SXL] = x0;
}

/* one TR-BDF2 step from the fraction fa to fb of the sample step: state in place, returns F_o, *F the force */
static double series_advance(int code, const double *p, double a, double ks, double half, double r, double theta,
                             double Ff, double Kp, double F0, double *state, double y0, double y1, double v0,
                             double v1, double a0, double a1, double dt, double fa, double fb, double h, bool jump,
                             double *F) {
    const double w = state[SW], u = state[SU], z = state[SZ], pw = state[SPW], xl = state[SXL];
    const double q = state[SQ], dq = state[SDQ];
    double W0 = state[SW0];
    const double g = TRBDF2_GAMMA;  /* trapezoidal rule to t + g h, then BDF2 (L-stable) */
    const double c_g = 1.0 / (g * (2.0 - g));
    const double c_0 = (1.0 - g) * (1.0 - g) / (g * (2.0 - g));
    const double c_h = (1.0 - g) / (2.0 - g) * h;
    const double fg = fa + g * (fb - fa);
    double ya, tr_g, tr_h;
    if (half > 0.0) {
        /* with a gap the pin's travel by the law's own rule (TR-BDF2 on w' = v - u, v linear) */
        ya = y0 + linear_travel(fa, dt, v0, v1);
        tr_g = 0.5 * g * h * ((v0 + (v1 - v0) * fa) + (v0 + (v1 - v0) * fg));
        tr_h = c_g * tr_g + c_h * (v0 + (v1 - v0) * fb);
    } else if (jump) {
        ya = y0 + (y1 - y0) * fa;
        tr_g = (y1 - y0) * (fg - fa);
        tr_h = (y1 - y0) * (fb - fa);
    } else {
        const double base = hermite_travel(fa, dt, v0, v1, a0, a1);
        ya = fa > 0.0 ? y0 + base : y0;
        tr_g = hermite_travel(fg, dt, v0, v1, a0, a1) - base;
        tr_h = hermite_travel(fb, dt, v0, v1, a0, a1) - base;
    }
    const double yg = ya + tr_g;
    const double yb = ((jump && half == 0.0) || fb >= 1.0) ? y0 + (y1 - y0) * fb : ya + tr_h;
    const double hf = theta != 0.0 ? heat_factor(theta, W0 + h * pw * J_TO_MJ) : 1.0;
    /* TR stage to t + g h */
    double wb = w + tr_g - 0.5 * g * h * u;
    const double hth = 0.5 * g * h;  /* law 7's trapezoidal stage: z + hth q phi(z) = z - hth q phi(z0) + travel */
    double zb = code == 7 ? z - hth * law7_rate(z, p) : 0.0;
    const Residual sg = series_stage(q + g * dq, a, code, p, yg, wb, hth, xl, z, zb, ks, half, r, hf, Ff, Kp, F0);
    const double pwg = sg.Fo * sg.u / hf;
    /* BDF2 stage to t + h */
    wb = c_g * sg.w - c_0 * w + tr_h - c_g * tr_g;
    const double qg = a != 1.0 ? powsign(sg.u, a) : sg.u;
    /* law 7's BDF2 stage: z1 - c_g z_g + c_0 z = travel terms - c_h q phi(z1) */
    zb = code == 7 ? c_g * sg.z - c_0 * z - c_0 * (yg - sg.w - xl) : 0.0;
    const Residual s1 = series_stage(qg + (1.0 - g) * dq, a, code, p, yb, wb, c_h, yg - sg.w, sg.z, zb, ks, half,
                                     r, hf, Ff, Kp, F0);
    const double pw1 = s1.Fo * s1.u / hf;
    W0 += (0.5 * g * h * (pw + pwg) + 0.5 * (1.0 - g) * h * (pwg + pw1)) * J_TO_MJ;
    const double q1 = a != 1.0 ? powsign(s1.u, a) : s1.u;
    state[SW] = s1.w; state[SU] = s1.u; state[SZ] = s1.z; state[SW0] = W0; state[SPW] = pw1;
    state[SXL] = yb - s1.w;
    state[SQ] = q1;
    state[SDQ] = q1 - q;  /* linear extrapolation of the next step's guess */
    *F = s1.R;
    return s1.Fo;
}

#define CONTACT_EDGE 1e-6
#define CONTACT_SPLITS 4
#define CONTACT_PIECES 4

static double contact_fraction(int code, const double *p, double a, double half, double r, double theta, double Ff,
                               double Kp, double F0, const double *state, double w1, double y0, double y1, double v0,
                               double v1, double a0, double a1, double dt, double fa, double fb, bool jump) {
    double trial[N_SPRING], F;
    const double w0 = state[SW];
    const double side = gap_side(w1, half);
    if (side == 0.0 || side == gap_side(w0, half)) return 0.0;
    if (gap_side(w0, half) != 0.0) return 0.5;
    double lo = 0.0, f_lo = side * w0 - half, hi = 1.0;
    memcpy(trial, state, sizeof(trial));
    series_advance(code, p, a, 0.0, half, r, theta, Ff, Kp, F0, trial, y0, y1, v0, v1, a0, a1, dt, fa, fb,
                   (fb - fa) * dt, jump, &F);
    double f_hi = side * trial[SW] - half;
    if (!(f_hi > 0.0)) return 0.0;  /* the free motion reaches h only at the end (to rounding) */
    double s = 1.0;
    int last = 0;
    for (int i = 0; i < 40; i++) {
        s = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
        const double f = fa + (fb - fa) * s;
        memcpy(trial, state, sizeof(trial));
        series_advance(code, p, a, 0.0, half, r, theta, Ff, Kp, F0, trial, y0, y1, v0, v1, a0, a1, dt, fa, f,
                       (f - fa) * dt, jump, &F);
        const double f_s = side * trial[SW] - half;
        if (f_s > 0.0) {
            hi = s;
            f_hi = f_s;
            if (last == 1) f_lo *= 0.5;  /* Illinois: the end kept twice is halved */
            last = 1;
        } else {
            lo = s;
            f_lo = f_s;
            if (last == -1) f_hi *= 0.5;
            last = -1;
        }
        if (fabs(f_s) <= 1e-12 * (1.0 + half) || hi - lo <= 1e-12) break;
    }
    if (s < CONTACT_EDGE || s > 1.0 - CONTACT_EDGE) return 0.0;
    return s;
}

static void series_sample(int code, const double *p, double a, double ks, double half, double r, double theta,
                          double Ff, double Kp, double F0, double *state, double y0, double y1, double v0, double v1,
                          double a0, double a1, double dt, int substeps, double *F, double *F_o) {
    const double h = dt / substeps;
    double fo = 0.0, f = 0.0;
    const bool jump = (v0 == 0.0) != (v1 == 0.0);
    for (int j = 0; j < substeps; j++) {
        const double f0 = (double)j / substeps, f1 = (double)(j + 1) / substeps;
        if (half == 0.0) {
            fo = series_advance(code, p, a, ks, half, r, theta, Ff, Kp, F0, state, y0, y1, v0, v1, a0, a1, dt, f0,
                                f1, h, jump, &f);
            continue;
        }
        double fa = f0;
        int pieces = 0;
        while (fa < f1) {
            double fb = f1;
            double next[N_SPRING];
            memcpy(next, state, sizeof(next));
            fo = series_advance(code, p, a, ks, half, r, theta, Ff, Kp, F0, next, y0, y1, v0, v1, a0, a1, dt, fa,
                                fb, (fb - fa) * dt, jump, &f);
            if (pieces < CONTACT_PIECES) {
                for (int i = 0; i < CONTACT_SPLITS; i++) {
                    const double s = contact_fraction(code, p, a, half, r, theta, Ff, Kp, F0, state, next[SW], y0,
                                                      y1, v0, v1, a0, a1, dt, fa, fb, jump);
                    if (s == 0.0) break;
                    fb = fa + (fb - fa) * s;
                    memcpy(next, state, sizeof(next));
                    fo = series_advance(code, p, a, ks, half, r, theta, Ff, Kp, F0, next, y0, y1, v0, v1, a0, a1,
                                        dt, fa, fb, (fb - fa) * dt, jump, &f);
                }
            }
            memcpy(state, next, sizeof(next));
            fa = fb;
            pieces++;
        }
    }
    *F = f;
    *F_o = fo;
}

/* ------------------------------------------------------ fvd_bridge/effects/scalar.py */
enum { GAP, SERIES, ASYMMETRY, THERMAL, FRICTION, PARALLEL, INERTIA };  /* EFFECT_NAMES */
enum { G, KS, R, THETA, FF, KP, F0, MASS };  /* PARAMETERS */

static void law_sample(int code, const double *k, double *s, double v0, double v1, double h, int substeps) {
    for (int j = 0; j < substeps; j++) {
        double va, vb;
        sub_velocities_(v0, v1, j, substeps, &va, &vb);
        advance(code, k, s, va, vb, h);
    }
}

/* first constant of each law's parameters, and their number (laws/catalog.py order) */
static const int LAW_FIRST[10] = {0, vr_law1_C, vr_law2_C, vr_law3_C, vr_law4_C, vr_law5_C, vr_law6_C, vr_law7_C,
                                  vr_law8_C, vr_law9_C};

/* compose._open_rows: a closed gap (g <= 0) or a rigid spring is the model without it */
static bool gap_on(const ModelData *m) {
    return m->flag[vr_gap_enabled] && m->value[vr_gap_g] > 0.0;
}

static bool series_on(const ModelData *m) {
    return m->flag[vr_series_stiffness_enabled] && !(m->value[vr_series_stiffness_Ks] >= KS_RIGID_FROM);
}

/* model_history's loop body for sample k (first: k = 0) with the pin's d [mm],
 * v [mm/s], a [mm/s^2] at the sample, dt [s] since the last one; returns F [kN] */
static double model_history_sample(ModelData *m, bool first, double d, double v, double a, double dt, int substeps) {
    const int code = m->law;
    const double *p_law = &m->value[LAW_FIRST[code]];
    const double *p_eff = &m->value[vr_gap_g];
    const bool *flags = &m->flag[vr_gap_enabled];
    const bool gap = gap_on(m);
    const bool series = series_on(m);
    const bool connected = gap || series;
    const double ks = series ? p_eff[KS] : INFINITY;  /* a gap alone: a rigid contact */
    const double half = gap ? gap_half(p_eff[G]) : 0.0;
    /* inside the connection an absent effect is its 'off' value (as compose._connection) */
    const double r = flags[ASYMMETRY] ? p_eff[R] : 0.0;
    const double theta = flags[THERMAL] ? p_eff[THETA] : 0.0;
    const double Ff = flags[FRICTION] ? p_eff[FF] : 0.0;
    const bool behind = gap && flags[PARALLEL];  /* the accumulator behind the clearance (compose.BEHIND_GAP) */
    const double kp = behind ? p_eff[KP] : 0.0;
    const double f0 = behind ? p_eff[F0] : 0.0;
    const double h = dt / substeps;
    const double x = d, xv = v, xa = a;
    double k_law[6], f, fo;
    law_constants(code, p_law, h, k_law);
    if (connected) {
        /* 1. the connection, with the law and the element effects inside */
        if (first) {
            series_rest(x, m->spring);
            f = 0.0;
        } else {
            series_sample(code, p_law, law_exponent(code, p_law), ks, half, r, theta, Ff, kp, f0, m->spring,
                          m->x0, x, m->xv0, xv, m->xa0, xa, dt, substeps, &f, &fo);
        }
    } else {
        /* 1. the law */
        if (!first) law_sample(code, k_law, m->s_law, m->xv0, xv, h, substeps);
        f = force(code, k_law, m->s_law, x, xv);
        /* 2. output */
        if (flags[ASYMMETRY]) f = f * asymmetry_factor(f, r);
        if (flags[THERMAL]) {
            const double p1 = f * xv;
            if (!first) {
                m->W0 = heat_energy(m->W0, m->power, p1, dt);
                f = f * heat_factor(theta, m->W0);
            }
            m->power = p1;
        }
        /* 3. parallel: friction on the law's velocity (inside the connection with one) */
        if (flags[FRICTION]) f = f + friction_term(Ff, xv);
    }
    /* 3. parallel */
    if (flags[PARALLEL] && !behind) f = f + parallel_spring(p_eff[KP], p_eff[F0], x);
    if (flags[INERTIA]) f = f + inertia_term(p_eff[MASS], xa);
    m->x0 = x; m->xv0 = xv; m->xa0 = xa;
    return f;
}

/* ------------------------------------------------------------------- the FMU model */

static const char *const NAME[N_VR] = VARIABLE_NAMES;

/* the law's internal variable z at the last sample (0 for laws 1-5 without a connection) */
static double internal_state(const ModelData *m) {
    if (gap_on(m) || series_on(m)) return m->spring[SZ];
    if (m->law == 7) return m->s_law[RHS] != 0.0 ? copysign(exp(m->s_law[LAM]), m->s_law[RHS]) : 0.0;
    if (m->law >= 6) return m->s_law[Z];
    return 0.0;
}

/* dx/dt [per s] at a new sample x from the last two, last[0] one step h [s]
 * back and last[1] h_last before it: the slope at the new sample of the
 * parabola through the three (BDF2 with variable steps, second order);
 * (x - last[0])/h while a single sample precedes */
static double backward_derivative(double x, const double *last, double h, double h_last, int32_t samples) {
    if (samples < 2) return (x - last[0]) / h;
    const double w = h / h_last;
    return ((1.0 + 2.0 * w) / (1.0 + w) * x - (1.0 + w) * last[0] + w * w / (1.0 + w) * last[1]) / h;
}

/* sub-steps of a communication step h [s]: ceil(h / h_max), a step within
 * 1e-9 above a multiple of h_max counting as that multiple */
static int substeps_of(double h, double h_max) {
    const double n = ceil(h / h_max * (1.0 - 1e-9));
    return n < 1.0 ? 1 : (n > 1e6 ? 1000000 : (int)n);
}

void setStartValues(ModelInstance *comp) {
    static const double start_float64[N_VR] = START_FLOAT64;
    static const bool start_boolean[N_VR] = START_BOOLEAN;
    memset(&comp->modelData, 0, sizeof(ModelData));
    memcpy(M(value), start_float64, sizeof(start_float64));
    memcpy(M(flag), start_boolean, sizeof(start_boolean));
    M(law) = START_LAW;
}

/* x in the fewest digits that read back as x (15, else 17) */
static const char *shortest(double x, char *buf, size_t size) {
    snprintf(buf, size, "%.15g", x);
    if (strtod(buf, NULL) != x) snprintf(buf, size, "%.17g", x);
    return buf;
}

static Status invalid(ModelInstance *comp, ValueReference vr, const char *rule) {
    char buf[32];
    logError(comp, "%s = %s: %s.", NAME[vr], shortest(M(value)[vr], buf, sizeof(buf)), rule);
    return Error;
}

#define REQUIRE(cond, vr, rule) do { if (!(cond)) return invalid(comp, vr, rule); } while (0)

/* the parameters of the active law and effects, where the equations need them */
static Status checkParameters(ModelInstance *comp) {
    const double *x = M(value);
    const bool *on = M(flag);
    REQUIRE(x[vr_h_max] > 0.0, vr_h_max, "the largest sub-step must be > 0 s");
    switch (M(law)) {
        case 2: case 3: case 4:
            REQUIRE(x[LAW_FIRST[M(law)] + 1] >= 0.0, LAW_FIRST[M(law)] + 1, "the damping exponent must be >= 0");
            break;
        case 5:
            REQUIRE(x[vr_law5_alpha] >= 0.0, vr_law5_alpha, "the damping exponent must be >= 0");
            REQUIRE(x[vr_law5_beta] >= 0.0, vr_law5_beta, "the spring exponent must be >= 0");
            break;
        case 6:
            REQUIRE(x[vr_law6_beta] >= 0.0, vr_law6_beta, "the hysteresis shape must be >= 0 1/mm");
            break;
        case 7:
            REQUIRE(x[vr_law7_C] > 0.0, vr_law7_C, "the dashpot coefficient must be > 0");
            REQUIRE(x[vr_law7_alpha] > 0.0, vr_law7_alpha, "the dashpot exponent must be > 0");
            REQUIRE(x[vr_law7_K] > 0.0, vr_law7_K, "the spring coefficient must be > 0");
            REQUIRE(x[vr_law7_beta] > 0.0, vr_law7_beta, "the spring exponent must be > 0");
            break;
        case 8:
            REQUIRE(x[vr_law8_K] >= 0.0, vr_law8_K, "the slip stiffness must be >= 0 kN/mm");
            REQUIRE(x[vr_law8_mu] * x[vr_law8_N] >= 0.0, vr_law8_N, "the slip force mu N must be >= 0 kN");
            break;
        case 9:
            REQUIRE(x[vr_law9_alpha] >= 0.0, vr_law9_alpha, "the inverse saturation travel must be >= 0 1/mm");
            break;
        default:
            break;
    }
    if (on[vr_gap_enabled]) REQUIRE(x[vr_gap_g] >= 0.0, vr_gap_g, "the clearance must be >= 0 mm");
    if (on[vr_series_stiffness_enabled])
        REQUIRE(x[vr_series_stiffness_Ks] > 0.0, vr_series_stiffness_Ks, "the series stiffness must be > 0 kN/mm");
    if (on[vr_asymmetry_enabled])
        REQUIRE(fabs(x[vr_asymmetry_r]) <= 1.0, vr_asymmetry_r, "the asymmetry must be within [-1, 1]");
    if (on[vr_thermal_softening_enabled])
        REQUIRE(x[vr_thermal_softening_theta] >= 0.0, vr_thermal_softening_theta, "the softening must be >= 0 1/MJ");
    if (on[vr_friction_enabled]) REQUIRE(x[vr_friction_Ff] >= 0.0, vr_friction_Ff, "the friction must be >= 0 kN");
    if (on[vr_inertia_enabled]) REQUIRE(x[vr_inertia_m] >= 0.0, vr_inertia_m, "the mass must be >= 0 kg");
    return OK;
}

static void setOutputs(ModelInstance *comp, double F) {
    M(value)[vr_F] = F;
    M(value)[vr_z] = internal_state(&comp->modelData);
}

static Status finiteOutputs(ModelInstance *comp) {
    if (isfinite(M(value)[vr_F]) && isfinite(M(value)[vr_z]) && isfinite(M(value)[vr_E])) return OK;
    logError(comp, "At t = %.17g s the damper's force, state or energy is not finite (F = %g kN, z = %g, "
                   "E = %g kN mm): the parameters or the inputs are out of the model's range.",
             comp->time, M(value)[vr_F], M(value)[vr_z], M(value)[vr_E]);
    return Error;
}

/* sample 0, at rest: the outputs at the start time from the inputs set so far */
Status initializeModel(ModelInstance *comp) {
    ModelData *m = &comp->modelData;
    if (checkParameters(comp) != OK) return Error;
    const double d = m->value[vr_d];
    const double v = m->flag[vr_use_velocity_input] ? m->value[vr_v] : 0.0;
    const double a = m->flag[vr_use_acceleration_input] ? m->value[vr_a] : 0.0;
    new_state(m->law, m->s_law);
    series_rest(0.0, m->spring);
    m->W0 = 0.0; m->power = 0.0;
    m->x0 = 0.0; m->xv0 = 0.0; m->xa0 = 0.0;
    const double F = model_history_sample(m, true, d, v, a, m->value[vr_h_max], 1);
    m->d_last[0] = m->d_last[1] = d;
    m->v_last[0] = m->v_last[1] = v;
    m->h_last = 0.0;
    m->samples = 1;
    m->Fv_last = F * v;
    m->value[vr_E] = 0.0;
    setOutputs(comp, F);
    return finiteOutputs(comp);
}

/* one communication step h [s] to the inputs set for its end */
Status doModelStep(ModelInstance *comp, double h) {
    ModelData *m = &comp->modelData;
    const int n = substeps_of(h, m->value[vr_h_max]);
    const double d = m->value[vr_d];
    const double v = m->flag[vr_use_velocity_input] ? m->value[vr_v]
                                                    : backward_derivative(d, m->d_last, h, m->h_last, m->samples);
    const double a = m->flag[vr_use_acceleration_input] ? m->value[vr_a]
                                                        : backward_derivative(v, m->v_last, h, m->h_last, m->samples);
    const double F = model_history_sample(m, false, d, v, a, h, n);
    m->value[vr_E] += 0.5 * h * (m->Fv_last + F * v);  /* work done on the damper, trapezoidal rule */
    m->Fv_last = F * v;
    m->d_last[1] = m->d_last[0]; m->d_last[0] = d;
    m->v_last[1] = m->v_last[0]; m->v_last[0] = v;
    m->h_last = h;
    m->samples++;
    setOutputs(comp, F);
    return finiteOutputs(comp);
}

/* ------------------------------------------------------------ variable access */

static bool isFloat64(ValueReference vr) {
    return vr == vr_time || (vr >= vr_d && vr <= vr_E) || (vr >= vr_h_max && vr < N_VR);
}

static bool isBoolean(ValueReference vr) {
    return vr >= vr_gap_enabled && vr <= vr_use_acceleration_input;
}

static Status wrongType(ModelInstance *comp, ValueReference vr, const char *type) {
    if ((int)vr < 0 || vr >= N_VR) {
        logError(comp, "Value reference %u does not exist.", (unsigned)vr);
    } else {
        logError(comp, "Variable %s (value reference %u) is not of type %s.", NAME[vr], (unsigned)vr, type);
    }
    return Error;
}

/* may a variable of this kind be set in the current state? */
static Status settable(ModelInstance *comp, ValueReference vr) {
    const ModelState s = comp->state;
    if (vr == vr_time || (vr >= vr_F && vr <= vr_E)) {
        logError(comp, "Variable %s is %s: it cannot be set.", NAME[vr], vr == vr_time ? "the time" : "an output");
        return Error;
    }
    if (vr >= vr_d && vr <= vr_a) {
        if (s & (Instantiated | InitializationMode | StepMode)) return OK;
    } else if (vr >= vr_law && vr <= vr_use_acceleration_input) {
        if (s & (Instantiated | ConfigurationMode)) return OK;
        logError(comp, "Variable %s is a structural parameter: it can be set only before initialization.", NAME[vr]);
        return Error;
    } else if (s & (Instantiated | InitializationMode)) {
        return OK;
    } else {
        logError(comp, "Variable %s is a fixed parameter: it can be set only before the end of initialization.",
                 NAME[vr]);
        return Error;
    }
    logError(comp, "Variable %s cannot be set in this state.", NAME[vr]);
    return Error;
}

Status getFloat64(ModelInstance *comp, ValueReference vr, double *value) {
    if (!isFloat64(vr)) return wrongType(comp, vr, "Float64");
    if (vr == vr_time) {
        *value = comp->time;
        return OK;
    }
    if (comp->state == InitializationMode && vr >= vr_F && vr <= vr_E && initializeModel(comp) != OK) return Error;
    *value = M(value)[vr];
    return OK;
}

Status setFloat64(ModelInstance *comp, ValueReference vr, double value) {
    if (!isFloat64(vr)) return wrongType(comp, vr, "Float64");
    if (settable(comp, vr) != OK) return Error;
    if (!isfinite(value) && !(vr == vr_series_stiffness_Ks && value == INFINITY)) {
        char buf[32];
        logError(comp, "%s = %s: %s must be a finite number.", NAME[vr], shortest(value, buf, sizeof(buf)),
                 vr <= vr_a ? "an input" : "a parameter");
        return Error;
    }
    M(value)[vr] = value;
    return OK;
}

Status getInt32(ModelInstance *comp, ValueReference vr, int32_t *value) {
    if (vr != vr_law) return wrongType(comp, vr, "Int32");
    *value = M(law);
    return OK;
}

Status setInt32(ModelInstance *comp, ValueReference vr, int32_t value) {
    if (vr != vr_law) return wrongType(comp, vr, "Int32");
    if (settable(comp, vr) != OK) return Error;
    if (value < 1 || value > 9) {
        logError(comp, "law = %d: the law's number must be 1-9.", (int)value);
        return Error;
    }
    M(law) = value;
    return OK;
}

Status getBoolean(ModelInstance *comp, ValueReference vr, bool *value) {
    if (!isBoolean(vr)) return wrongType(comp, vr, "Boolean");
    *value = M(flag)[vr];
    return OK;
}

Status setBoolean(ModelInstance *comp, ValueReference vr, bool value) {
    if (!isBoolean(vr)) return wrongType(comp, vr, "Boolean");
    if (settable(comp, vr) != OK) return Error;
    M(flag)[vr] = value;
    return OK;
}
