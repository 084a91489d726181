/* The damper between two samples: the state of effects.c's composition
 * (hand-kept; laws.c and effects.c
 * advance it, model.c keeps it in the FMU's model data).  Units: kN, mm, s.
 */
#ifndef damper_h
#define damper_h

#define N_LAW_STATE 13 /* laws.scalar: Z, C_PHI, ..., DONE */
#define N_SPRING 8     /* series_rest: (w, u, z, W0, pw, x_o, q, dq) */

typedef struct {
    double s_law[N_LAW_STATE]; /* the law's state (laws.scalar.new_state) */
    double spring[N_SPRING];   /* the connection's state: series spring and gap (series_rest) */
    double W0, power;          /* heating: energy of the unsoftened law [MJ], its last power [kN mm/s] */
    double x0, xv0, xa0;       /* the pin's motion at the last sample [mm, mm/s, mm/s^2] */
} Damper;

#endif /* damper_h */
