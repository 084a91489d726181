/* The effects and their composition with the law: fvd_bridge's built-in
 * effects for one member, sample by sample.  Part of the damper FMU's
 * physics (hand-kept); model.c compiles it into its translation unit after
 * laws.c (#include "effects.c"), so every function stays static.  Units: kN,
 * mm, s, mass kg.
 *
 * Mirrors, function for function and with the same names, the Python
 * reference step forms (conventions as in laws.c):
 *   fvd_bridge/effects/steps.py       asymmetry_factor ... heat_energy
 *   fvd_bridge/effects/element.py     algebraic_law ... element_force (the
 *                                     law behind a connection)
 *   fvd_bridge/effects/connection.py  hermite_travel ... series_sample (the
 *                                     series spring and the contact gap)
 * and composes them with the law in the order of fvd_bridge/effects/compose.py
 * (the composition, written once in each language: model_history_sample, k
 * = 0 at initialization, k > 0 in each fmi3DoStep; tested against the Python
 * model).  The effects are flags (fvd_bridge.effects.catalog.BUILTIN order)
 * and parameters p_eff (EFFECT_PARAMETERS order), the layout of config.h's
 * EFFECT_ENABLED_VR and EFFECT_PAR_VR.
 */
#include <math.h>
#include <stdbool.h>
#include <string.h>

#include "config.h"
#include "damper.h"

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

static void series_rest(double x0, double Ks, double half, double Kp, double F0, double *state) {
    memset(state, 0, N_SPRING * sizeof(double));
    if (half == 0.0 && !isinf(Ks) && Ks + Kp > 0.0) state[SW] = (Kp * x0 + F0) / (Ks + Kp);
    state[SXL] = x0 - state[SW];
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

/* ------------------------------------ the composition (fvd_bridge/effects/compose.py) */
enum { GAP, SERIES, OIL, ASYMMETRY, THERMAL, FRICTION, PARALLEL, INERTIA };  /* effects.catalog.BUILTIN */
enum { G, KS, KO, R, THETA, FF, KP, F0, MASS };  /* effects.catalog.EFFECT_PARAMETERS */

static void law_sample(int code, const double *k, double *s, double v0, double v1, double h, int substeps) {
    for (int j = 0; j < substeps; j++) {
        double va, vb;
        sub_velocities_(v0, v1, j, substeps, &va, &vb);
        advance(code, k, s, va, vb, h);
    }
}


/* config.h's tables follow the registry: it must hold these effects in this order */
typedef char effects_match_the_registry[(N_EFFECTS == INERTIA + 1 && N_EFFECT_PAR == MASS + 1) ? 1 : -1];

/* compose._open_rows: a closed gap (g <= 0) or a rigid spring is the model without it */
static bool gap_on(const bool *flags, const double *p_eff) {
    return flags[GAP] && p_eff[G] > 0.0;
}

static bool series_on(const bool *flags, const double *p_eff) {
    return flags[SERIES] && !(p_eff[KS] >= KS_RIGID_FROM);
}

static bool oil_on(const bool *flags, const double *p_eff) {
    return flags[OIL] && !(p_eff[KO] >= KS_RIGID_FROM);
}

/* is the law behind a connection (a series spring, an oil column or an open gap)? */
static bool connection_on(const bool *flags, const double *p_eff) {
    return gap_on(flags, p_eff) || series_on(flags, p_eff) || oil_on(flags, p_eff);
}

/* Model.refusal: one spring, and no effect behind one connection but beside another (the seal and the
 * accumulator sit behind a gap but beside an oil column); the rule broken, NULL when there is none */
static const char *arrangement_problem(const bool *flags) {
    if (flags[SERIES] && flags[OIL]) return "series_stiffness and oil_column both set the series spring";
    if (flags[GAP] && flags[OIL] && (flags[FRICTION] || flags[PARALLEL]))
        return "friction and parallel_stiffness would sit behind the gap but beside the oil column";
    return NULL;
}

/* the damper's force at sample k (first: k = 0) of law `code` with
 * parameters p_law and the effects (flags, p_eff), the pin's d [mm], v
 * [mm/s], a [mm/s^2] at the sample, dt [s] since the last one; the damper's
 * state m in place; returns F [kN] */
static double model_history_sample(Damper *m, int code, const double *p_law, const bool *flags, const double *p_eff,
                                   bool first, double d, double v, double a, double dt, int substeps) {
    const bool gap = gap_on(flags, p_eff);
    const bool series = series_on(flags, p_eff);
    const bool oil = oil_on(flags, p_eff);
    const bool connected = gap || series || oil;
    /* a gap alone: a rigid contact */
    const double ks = series ? p_eff[KS] : (oil ? p_eff[KO] : INFINITY);
    const double half = gap ? gap_half(p_eff[G]) : 0.0;
    /* inside the connection an absent effect is its 'off' value (as compose._connection) */
    const double r = flags[ASYMMETRY] ? p_eff[R] : 0.0;
    const double theta = flags[THERMAL] ? p_eff[THETA] : 0.0;
    /* the seal and the accumulator: behind a series spring or a gap, beside an oil column (catalog.OUTSIDE) */
    const bool rod = connected && !oil;
    const bool seal_behind = rod && flags[FRICTION];
    const double Ff = seal_behind ? p_eff[FF] : 0.0;
    const bool behind = rod && flags[PARALLEL];
    const double kp = behind ? p_eff[KP] : 0.0;
    const double f0 = behind ? p_eff[F0] : 0.0;
    const double h = dt / substeps;
    const double x = d, xv = v, xa = a;
    double k_law[6], f, fo;
    law_constants(code, p_law, h, k_law);
    if (connected) {
        /* 1. the connection, with the law and the element effects inside */
        if (first) {
            series_rest(x, ks, half, kp, f0, m->spring);
            f = m->spring[SW] != 0.0 ? ks * m->spring[SW] : 0.0;
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
    }
    /* 3. parallel: the seal on the rod's velocity (solved inside a series spring or a gap) */
    if (flags[FRICTION] && !seal_behind) f = f + friction_term(p_eff[FF], xv);
    if (flags[PARALLEL] && !behind) f = f + parallel_spring(p_eff[KP], p_eff[F0], x);
    if (flags[INERTIA]) f = f + inertia_term(p_eff[MASS], xa);
    m->x0 = x; m->xv0 = xv; m->xa0 = xa;
    return f;
}

/* the damper at rest before sample 0: the law's and the connection's state zero */
static void model_rest(Damper *m, int code) {
    new_state(code, m->s_law);
    series_rest(0.0, INFINITY, 0.0, 0.0, 0.0, m->spring);
    m->W0 = 0.0; m->power = 0.0;
    m->x0 = 0.0; m->xv0 = 0.0; m->xa0 = 0.0;
}

/* the law's internal variable z at the last sample (law 10: its spring force F [kN]; 0 for laws 1-5 without a
 * connection) */
static double internal_state(const Damper *m, int code, bool connection) {
    if (connection) return m->spring[SZ];
    if (code == 7) return m->s_law[RHS] != 0.0 ? copysign(exp(m->s_law[LAM]), m->s_law[RHS]) : 0.0;
    if (code >= 6) return m->s_law[Z];
    return 0.0;
}

/* The first effect parameter (p_eff, PARAMETERS order) of an enabled effect
 * whose value its equation cannot take: its index into *index and the rule
 * it breaks; NULL when there is none. */
static const char *effect_parameter_problem(const bool *flags, const double *p_eff, int *index) {
#define RULE(effect, cond, i, rule) do { \
        if (flags[effect] && !(cond)) { *index = (i); return (rule); } } while (0)
    RULE(GAP, p_eff[G] >= 0.0, G, "the clearance must be >= 0 mm");
    RULE(SERIES, p_eff[KS] > 0.0, KS, "the series stiffness must be > 0 kN/mm");
    RULE(OIL, p_eff[KO] > 0.0, KO, "the oil column's stiffness must be > 0 kN/mm");
    RULE(ASYMMETRY, fabs(p_eff[R]) <= 1.0, R, "the asymmetry must be within [-1, 1]");
    RULE(THERMAL, p_eff[THETA] >= 0.0, THETA, "the softening must be >= 0 1/MJ");
    RULE(FRICTION, p_eff[FF] >= 0.0, FF, "the friction must be >= 0 kN");
    RULE(INERTIA, p_eff[MASS] >= 0.0, MASS, "the mass must be >= 0 kg");
    return NULL;
#undef RULE
}
