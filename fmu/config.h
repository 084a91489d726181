/* The damper FMU's configuration: identifier, value references, model data.
 *
 * One model for the nine laws and the seven built-in effects of fvd_bridge,
 * chosen by structural parameters.  The value references are the order of
 * the variables in modelDescription.xml (tests/test_export_fmu.py checks
 * it).  calibration.h, written by fvd_bridge.export.fmu.build_fmu, holds
 * the instantiation token and the calibrated start values.  Units: kN, mm, s,
 * mass kg.
 */
#ifndef config_h
#define config_h

#include <stdbool.h>
#include <stdint.h>

#define MODEL_IDENTIFIER fvd_damper

typedef enum {
    vr_time,
    /* inputs: the pin's motion at the END of the coming communication step */
    vr_d, vr_v, vr_a,
    /* outputs */
    vr_F, vr_z, vr_E,
    /* structural parameters */
    vr_law,
    vr_gap_enabled, vr_series_stiffness_enabled, vr_asymmetry_enabled, vr_thermal_softening_enabled,
    vr_friction_enabled, vr_parallel_stiffness_enabled, vr_inertia_enabled,
    vr_use_velocity_input, vr_use_acceleration_input,
    /* parameters */
    vr_h_max,
    vr_law1_C,
    vr_law2_C, vr_law2_alpha,
    vr_law3_C, vr_law3_alpha, vr_law3_K1,
    vr_law4_C, vr_law4_alpha, vr_law4_K1, vr_law4_K2,
    vr_law5_C, vr_law5_alpha, vr_law5_K, vr_law5_beta,
    vr_law6_C, vr_law6_K, vr_law6_alpha, vr_law6_beta,
    vr_law7_C, vr_law7_alpha, vr_law7_K, vr_law7_beta,
    vr_law8_C, vr_law8_K, vr_law8_mu, vr_law8_N,
    vr_law9_C, vr_law9_alpha, vr_law9_beta,
    /* the effects' parameters, in fvd_bridge.effects.scalar.PARAMETERS order */
    vr_gap_g, vr_series_stiffness_Ks, vr_asymmetry_r, vr_thermal_softening_theta, vr_friction_Ff,
    vr_parallel_stiffness_Kp, vr_parallel_stiffness_F0, vr_inertia_m,
    N_VR
} ValueReference;

#define N_LAW_STATE 13 /* laws.scalar: Z, C_PHI, ..., DONE */
#define N_SPRING 8    /* effects.steps.series_rest: (w, u, z, W0, pw, x_o, q, dq) */

typedef struct {
    /* variables */
    double value[N_VR];          /* every Float64 variable, by value reference */
    bool flag[N_VR];             /* every Boolean variable, by value reference */
    int32_t law;                 /* the law's number, 1-9 */
    /* the damper between communication points: model_history's loop variables */
    double s_law[N_LAW_STATE];   /* the law's state (laws.scalar.new_state) */
    double spring[N_SPRING];     /* the connection's state: series spring and gap (effects.steps.series_rest) */
    double W0, power;            /* heating: energy of the unsoftened law [MJ], its last power [kN mm/s] */
    double x0, xv0, xa0;         /* the pin's motion at the last sample [mm, mm/s, mm/s^2] */
    double d_last[2], v_last[2]; /* the pin's d [mm], v [mm/s] at the last two samples */
    double h_last;               /* the last communication step [s] */
    double Fv_last;              /* F v at the last sample [kN mm/s] (energy) */
    int32_t samples;             /* samples taken since rest */
} ModelData;

#include "calibration.h"

#endif /* config_h */
