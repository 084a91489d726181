/* The interface between the FMI 3 layer (fmi3Functions.c) and the damper
 * (model.c, with the physics of laws.c and effects.c).  Adapted from the
 * Modelica Reference-FMUs, include/model.h
 * (https://github.com/modelica/Reference-FMUs), reduced to FMI 3.0
 * co-simulation; the original licence follows.
 *
 * Copyright (c) 2026, Modelica Association Project "FMI".
 * All rights reserved.
 *
 * The Reference FMUs are released under the 2-Clause BSD license:
 *
 * Redistribution and use in source and binary forms, with or without
 * modification, are permitted provided that the following conditions are met:
 *
 * 1. Redistributions of source code must retain the above copyright notice, this
 *    list of conditions and the following disclaimer.
 *
 * 2. Redistributions in binary form must reproduce the above copyright notice,
 *    this list of conditions and the following disclaimer in the documentation
 *    and/or other materials provided with the distribution.
 *
 * THIS SOFTWARE IS PROVIDED BY THE COPYRIGHT HOLDERS AND CONTRIBUTORS "AS IS" AND
 * ANY EXPRESS OR IMPLIED WARRANTIES, INCLUDING, BUT NOT LIMITED TO, THE IMPLIED
 * WARRANTIES OF MERCHANTABILITY AND FITNESS FOR A PARTICULAR PURPOSE ARE
 * DISCLAIMED. IN NO EVENT SHALL THE COPYRIGHT HOLDER OR CONTRIBUTORS BE LIABLE FOR
 * ANY DIRECT, INDIRECT, INCIDENTAL, SPECIAL, EXEMPLARY, OR CONSEQUENTIAL DAMAGES
 * (INCLUDING, BUT NOT LIMITED TO, PROCUREMENT OF SUBSTITUTE GOODS OR SERVICES;
 * LOSS OF USE, DATA, OR PROFITS; OR BUSINESS INTERRUPTION) HOWEVER CAUSED AND
 * ON ANY THEORY OF LIABILITY, WHETHER IN CONTRACT, STRICT LIABILITY, OR TORT
 * (INCLUDING NEGLIGENCE OR OTHERWISE) ARISING IN ANY WAY OUT OF THE USE OF THIS
 * SOFTWARE, EVEN IF ADVISED OF THE POSSIBILITY OF SUCH DAMAGE.
 */
#ifndef model_h
#define model_h

#include <stddef.h>
#include <stdbool.h>
#include <stdint.h>

#include "config.h"
#include "damper.h"

#define UNUSED(x) (void)(x)

/* the damper FMU's data (model.c): variables by value reference (config.h, generated) and state */
/* the damper at one sample: its state and the history its next step reads */
typedef struct {
    Damper damper;               /* the composition's state (damper.h) */
    double d_last[2], v_last[2]; /* the pin's d [mm], v [mm/s] at the last two samples */
    double h_last;               /* the last communication step [s] */
    double Fv_last;              /* F v at the last sample [kN mm/s] (energy) */
    double E;                    /* work done on the damper so far [kN mm] */
    int32_t samples;             /* samples taken since rest */
} Track;

typedef struct {
    /* variables */
    double value[N_VR];          /* every Float64 variable, by value reference */
    bool flag[N_VR];             /* every Boolean variable, by value reference */
    int32_t law;                 /* the law's number (config.h: LAW_IN_FMU) */
    bool v_set, a_set;           /* the master has set v, a (they are then used as given) */
    /* the damper between communication points */
    Track now;                   /* at the last sample computed */
    Track at_t;                  /* at the communication point t (inputs at the step's start) */
    bool predicted;              /* now is at t + h from predicted inputs: redone when the inputs at t + h come */
    double h_predicted;          /* that step [s] */
    double in_hist[3][3];        /* the inputs d, v, a at the last three communication points (newest first) */
    double h_hist[2];            /* the steps between them [s] */
    int32_t points;              /* communication points seen */
    bool on[N_EFFECTS];          /* the effects' switches (EFFECT_NAMES order), set at initialization */
    double p_eff[N_EFFECT_PAR];  /* the effects' parameters (PARAMETERS order), as last checked */
    bool connection;             /* the law is behind a connection (fixed at initialization) */
} ModelData;

typedef enum {
    StartAndEnd            = 1 << 0,
    ConfigurationMode      = 1 << 1,
    Instantiated           = 1 << 2,
    InitializationMode     = 1 << 3,
    EventMode              = 1 << 4,
    ContinuousTimeMode     = 1 << 5,
    StepMode               = 1 << 6,
    ClockActivationMode    = 1 << 7,
    StepDiscarded          = 1 << 8,
    ReconfigurationMode    = 1 << 9,
    IntermediateUpdateMode = 1 << 10,
    Terminated             = 1 << 11,
} ModelState;

typedef enum { OK, Warning, Discard, Error, Fatal } Status;

typedef void (*loggerType) (void *componentEnvironment, int status, const char *category, const char *message);

typedef struct {
    double startTime;
    double stopTime;
    double time;
    double nextCommunicationPoint;
    char *instanceName;
    loggerType logger;
    void *componentEnvironment;
    bool logEvents;
    bool logErrors;
    ModelState state;
    ModelData modelData;
} ModelInstance;

/* what fmi3GetFMUState saves: the time and the model data, tagged with the token */
typedef struct {
    char token[64];
    double time;
    double nextCommunicationPoint;
    ModelState state;
    ModelData modelData;
} SavedState;

/* model.c */
void setStartValues(ModelInstance *comp);
Status initializeModel(ModelInstance *comp);
Status doModelStep(ModelInstance *comp, double h);
Status getFloat64(ModelInstance *comp, ValueReference vr, double *value);
Status setFloat64(ModelInstance *comp, ValueReference vr, double value);
Status getInt32(ModelInstance *comp, ValueReference vr, int32_t *value);
Status setInt32(ModelInstance *comp, ValueReference vr, int32_t value);
Status getBoolean(ModelInstance *comp, ValueReference vr, bool *value);
Status setBoolean(ModelInstance *comp, ValueReference vr, bool value);

/* fmi3Functions.c */
void logError(ModelInstance *comp, const char *message, ...);
void logEvent(ModelInstance *comp, const char *message, ...);

/* shorthand to access the model data */
#define M(v) (comp->modelData.v)

#endif /* model_h */
