/* The FMI 3.0 co-simulation layer of the damper FMU: instance life cycle,
 * variable access, FMU state, fmi3DoStep; every other function of the
 * standard is present and returns fmi3Error (Model Exchange and Scheduled
 * Execution are not offered).  The physics is in model.c.
 *
 * Adapted from the Modelica Reference-FMUs, src/fmi3Functions.c and
 * src/cosimulation.c (https://github.com/modelica/Reference-FMUs): their
 * state masks, call macros, logging and FMU-state functions, reduced to
 * co-simulation with a fixed set of variable types.  The original licence
 * follows.
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
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model.h"

/* Without FMI3_FUNCTION_PREFIX the functions carry their plain names, as a
 * shared library needs; define it (e.g. fvd_damper_) to link statically. */
#include "fmi3Functions.h"

/* ------------------------------------------------------------------ logging */

static void logVMessage(ModelInstance *comp, int status, const char *category, const char *message, va_list args) {
    char buf[1024];
    if (!comp->logger) return;
    vsnprintf(buf, sizeof(buf), message, args);
    comp->logger(comp->componentEnvironment, status, category, buf);
}

void logEvent(ModelInstance *comp, const char *message, ...) {
    if (!comp || !comp->logEvents) return;
    va_list args;
    va_start(args, message);
    logVMessage(comp, OK, "logEvents", message, args);
    va_end(args);
}

void logError(ModelInstance *comp, const char *message, ...) {
    if (!comp || !comp->logErrors) return;
    va_list args;
    va_start(args, message);
    logVMessage(comp, Error, "logStatusError", message, args);
    va_end(args);
}

/* ------------------------------------------------- state masks and call macros */

#define MASK_AnyState (~0)
#define MASK_EnterInitializationMode Instantiated
#define MASK_ExitInitializationMode InitializationMode
#define MASK_Terminate (StepMode | StepDiscarded)
#define MASK_GetValues (Instantiated | InitializationMode | ConfigurationMode | StepMode | StepDiscarded | Terminated)
#define MASK_SetValues (Instantiated | InitializationMode | ConfigurationMode | StepMode)
#define MASK_EnterConfigurationMode Instantiated
#define MASK_ExitConfigurationMode ConfigurationMode
#define MASK_EnterStepMode InitializationMode
#define MASK_DoStep StepMode

#define BEGIN_FUNCTION(F) \
    Status status = OK; \
    if (!instance) return fmi3Error; \
    ModelInstance *S = (ModelInstance *)instance; \
    if (!allowedState(S, MASK_##F, #F)) CALL(Error);

#define END_FUNCTION() \
TERMINATE: \
    return (fmi3Status)status;

/* an Error ends the instance's life (Terminated), as in the Reference-FMUs */
#define CALL(f) do { \
    const Status s_ = f; \
    if (s_ > status) status = s_; \
    if (status == Error) { S->state = Terminated; goto TERMINATE; } \
    if (status == Fatal) { S->state = StartAndEnd; goto TERMINATE; } \
} while (0)

#define ASSERT_NOT_NULL(p) do { \
    if (!(p)) { logError(S, "Argument %s must not be NULL.", #p); CALL(Error); } \
} while (0)

#define NOT_IMPLEMENTED(F) do { \
    if (instance) logError((ModelInstance *)instance, "fmi3" #F " is not supported (co-simulation only)."); \
    return fmi3Error; \
} while (0)

static bool allowedState(ModelInstance *comp, int statesExpected, const char *name) {
    if (!(comp->state & statesExpected)) {
        logError(comp, "fmi3%s: Illegal call sequence.", name);
        return false;
    }
    return true;
}

/* Reference-FMUs' isClose: |a - b| <= 1e-5, absolute or relative */
static bool isClose(double a, double b) {
    const double d = fabs(a - b);
    return d <= 1e-5 || d <= 1e-5 * fmax(fabs(a), fabs(b));
}

/* ------------------------------------------------------- creation, life cycle */

const char *fmi3GetVersion(void) {
    return fmi3Version;
}

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
    BEGIN_FUNCTION(AnyState);
    if (nCategories == 0) {
        S->logEvents = loggingOn;
        S->logErrors = loggingOn;
    }
    for (size_t i = 0; i < nCategories; i++) {
        if (!categories || !categories[i]) {
            logError(S, "Argument categories[%zu] must not be NULL.", i);
            CALL(Error);
        } else if (strcmp(categories[i], "logEvents") == 0) {
            S->logEvents = loggingOn;
        } else if (strcmp(categories[i], "logStatusError") == 0) {
            S->logErrors = loggingOn;
        } else {
            logError(S, "Log category \"%s\" must be one of \"logEvents\" or \"logStatusError\".", categories[i]);
            CALL(Error);
        }
    }
    END_FUNCTION();
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage) {
    UNUSED(instanceName); UNUSED(instantiationToken); UNUSED(resourcePath); UNUSED(visible); UNUSED(loggingOn);
    if (logMessage) logMessage(instanceEnvironment, fmi3Error, "logStatusError", "Model Exchange is not supported.");
    return NULL;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate) {
    UNUSED(resourcePath); UNUSED(visible); UNUSED(earlyReturnAllowed); UNUSED(requiredIntermediateVariables);
    UNUSED(nRequiredIntermediateVariables); UNUSED(intermediateUpdate);
    const char *refusal = NULL;
    if (!instanceName || !instanceName[0]) {
        refusal = "Missing instance name.";
    } else if (!instantiationToken || strcmp(instantiationToken, INSTANTIATION_TOKEN) != 0) {
        refusal = "Wrong instantiationToken: this binary belongs to another modelDescription.xml.";
    } else if (eventModeUsed) {
        refusal = "Event Mode is not supported.";
    }
    if (refusal) {
        if (logMessage) logMessage(instanceEnvironment, fmi3Error, "logStatusError", refusal);
        return NULL;
    }
    ModelInstance *comp = (ModelInstance *)calloc(1, sizeof(ModelInstance));
    const size_t n = strlen(instanceName) + 1;
    if (comp) comp->instanceName = (char *)malloc(n);
    if (!comp || !comp->instanceName) {
        if (logMessage) logMessage(instanceEnvironment, fmi3Error, "logStatusError", "Out of memory.");
        free(comp);
        return NULL;
    }
    memcpy(comp->instanceName, instanceName, n);
    comp->logger = (loggerType)logMessage;
    comp->componentEnvironment = instanceEnvironment;
    comp->logEvents = loggingOn;
    comp->logErrors = true;  /* always log errors */
    comp->state = Instantiated;
    setStartValues(comp);
    return comp;
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible,
                                               fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage,
                                               fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption) {
    UNUSED(instanceName); UNUSED(instantiationToken); UNUSED(resourcePath); UNUSED(visible); UNUSED(loggingOn);
    UNUSED(clockUpdate); UNUSED(lockPreemption); UNUSED(unlockPreemption);
    if (logMessage) {
        logMessage(instanceEnvironment, fmi3Error, "logStatusError", "Scheduled Execution is not supported.");
    }
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance) {
    ModelInstance *comp = (ModelInstance *)instance;
    if (!comp) return;
    free(comp->instanceName);
    free(comp);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    UNUSED(toleranceDefined); UNUSED(tolerance);
    BEGIN_FUNCTION(EnterInitializationMode);
    S->startTime = startTime;
    S->stopTime = stopTimeDefined ? stopTime : INFINITY;
    S->time = startTime;
    S->nextCommunicationPoint = startTime;
    S->state = InitializationMode;
    END_FUNCTION();
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    BEGIN_FUNCTION(ExitInitializationMode);
    CALL(initializeModel(S));
    S->state = StepMode;
    END_FUNCTION();
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    NOT_IMPLEMENTED(EnterEventMode);
}

fmi3Status fmi3Terminate(fmi3Instance instance) {
    BEGIN_FUNCTION(Terminate);
    S->state = Terminated;
    END_FUNCTION();
}

fmi3Status fmi3Reset(fmi3Instance instance) {
    BEGIN_FUNCTION(AnyState);
    S->state = Instantiated;
    S->startTime = S->time = S->nextCommunicationPoint = 0.0;
    setStartValues(S);
    END_FUNCTION();
}

/* ------------------------------------------------------------ variable access */

#define GET_VARIABLES(T, CT) \
    BEGIN_FUNCTION(GetValues); \
    if (nValueReferences == 0) goto TERMINATE; \
    ASSERT_NOT_NULL(valueReferences); \
    ASSERT_NOT_NULL(values); \
    if (nValues != nValueReferences) { \
        logError(S, "Expected nValues = %zu but was %zu.", nValueReferences, nValues); \
        CALL(Error); \
    } \
    for (size_t i = 0; i < nValueReferences; i++) { \
        CT value_; \
        CALL(get##T(S, (ValueReference)valueReferences[i], &value_)); \
        values[i] = value_; \
    } \
    END_FUNCTION()

#define SET_VARIABLES(T, CT) \
    BEGIN_FUNCTION(SetValues); \
    if (nValueReferences == 0) goto TERMINATE; \
    ASSERT_NOT_NULL(valueReferences); \
    ASSERT_NOT_NULL(values); \
    if (nValues != nValueReferences) { \
        logError(S, "Expected nValues = %zu but was %zu.", nValueReferences, nValues); \
        CALL(Error); \
    } \
    for (size_t i = 0; i < nValueReferences; i++) { \
        CALL(set##T(S, (ValueReference)valueReferences[i], (CT)values[i])); \
    } \
    END_FUNCTION()

#define WRONG_TYPE(T) do { \
    UNUSED(valueReferences); UNUSED(nValueReferences); UNUSED(values); UNUSED(nValues); \
    if (instance) logError((ModelInstance *)instance, "This FMU has no variable of type " #T "."); \
    return fmi3Error; \
} while (0)

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          fmi3Float64 values[], size_t nValues) {
    GET_VARIABLES(Float64, double);
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          const fmi3Float64 values[], size_t nValues) {
    SET_VARIABLES(Float64, double);
}

fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        fmi3Int32 values[], size_t nValues) {
    GET_VARIABLES(Int32, int32_t);
}

fmi3Status fmi3SetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        const fmi3Int32 values[], size_t nValues) {
    SET_VARIABLES(Int32, int32_t);
}

fmi3Status fmi3GetBoolean(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          fmi3Boolean values[], size_t nValues) {
    GET_VARIABLES(Boolean, bool);
}

fmi3Status fmi3SetBoolean(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          const fmi3Boolean values[], size_t nValues) {
    SET_VARIABLES(Boolean, bool);
}

#define NO_VARIABLES_OF_TYPE(T, CT, CONST) \
fmi3Status fmi3Get##T(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, \
                      CT values[], size_t nValues) { WRONG_TYPE(T); } \
fmi3Status fmi3Set##T(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, \
                      CONST CT values[], size_t nValues) { WRONG_TYPE(T); }

NO_VARIABLES_OF_TYPE(Float32, fmi3Float32, const)
NO_VARIABLES_OF_TYPE(Int8, fmi3Int8, const)
NO_VARIABLES_OF_TYPE(UInt8, fmi3UInt8, const)
NO_VARIABLES_OF_TYPE(Int16, fmi3Int16, const)
NO_VARIABLES_OF_TYPE(UInt16, fmi3UInt16, const)
NO_VARIABLES_OF_TYPE(UInt32, fmi3UInt32, const)
NO_VARIABLES_OF_TYPE(Int64, fmi3Int64, const)
NO_VARIABLES_OF_TYPE(UInt64, fmi3UInt64, const)
NO_VARIABLES_OF_TYPE(String, fmi3String, const)

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         size_t valueSizes[], fmi3Binary values[], size_t nValues) {
    UNUSED(valueSizes);
    WRONG_TYPE(Binary);
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         const size_t valueSizes[], const fmi3Binary values[], size_t nValues) {
    UNUSED(valueSizes);
    WRONG_TYPE(Binary);
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        fmi3Clock values[]) {
    UNUSED(valueReferences); UNUSED(nValueReferences); UNUSED(values);
    NOT_IMPLEMENTED(GetClock);
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        const fmi3Clock values[]) {
    UNUSED(valueReferences); UNUSED(nValueReferences); UNUSED(values);
    NOT_IMPLEMENTED(SetClock);
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference,
                                               size_t *nDependencies) {
    UNUSED(valueReference); UNUSED(nDependencies);
    NOT_IMPLEMENTED(GetNumberOfVariableDependencies);
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies) {
    UNUSED(dependent); UNUSED(elementIndicesOfDependent); UNUSED(independents);
    UNUSED(elementIndicesOfIndependents); UNUSED(dependencyKinds); UNUSED(nDependencies);
    NOT_IMPLEMENTED(GetVariableDependencies);
}

/* ---------------------------------------------------------------- FMU state */

static void saveState(const ModelInstance *comp, SavedState *saved) {
    memset(saved, 0, sizeof(SavedState));
    strncpy(saved->token, INSTANTIATION_TOKEN, sizeof(saved->token) - 1);
    saved->time = comp->time;
    saved->nextCommunicationPoint = comp->nextCommunicationPoint;
    saved->state = comp->state;
    saved->modelData = comp->modelData;
}

static Status restoreState(ModelInstance *comp, const SavedState *saved) {
    if (strncmp(saved->token, INSTANTIATION_TOKEN, sizeof(saved->token)) != 0) {
        logError(comp, "The FMU state belongs to another FMU (instantiation token %.63s).", saved->token);
        return Error;
    }
    comp->time = saved->time;
    comp->nextCommunicationPoint = saved->nextCommunicationPoint;
    comp->state = saved->state;
    comp->modelData = saved->modelData;
    return OK;
}

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    BEGIN_FUNCTION(AnyState);
    ASSERT_NOT_NULL(FMUState);
    if (!*FMUState) *FMUState = malloc(sizeof(SavedState));
    if (!*FMUState) {
        logError(S, "Out of memory.");
        CALL(Error);
    }
    saveState(S, (SavedState *)*FMUState);
    END_FUNCTION();
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState) {
    BEGIN_FUNCTION(AnyState);
    ASSERT_NOT_NULL(FMUState);
    CALL(restoreState(S, (const SavedState *)FMUState));
    END_FUNCTION();
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    BEGIN_FUNCTION(AnyState);
    if (FMUState) {
        free(*FMUState);
        *FMUState = NULL;
    }
    END_FUNCTION();
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t *size) {
    UNUSED(FMUState);
    BEGIN_FUNCTION(AnyState);
    ASSERT_NOT_NULL(size);
    *size = sizeof(SavedState);
    END_FUNCTION();
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[],
                                 size_t size) {
    BEGIN_FUNCTION(AnyState);
    ASSERT_NOT_NULL(FMUState);
    ASSERT_NOT_NULL(serializedState);
    if (size != sizeof(SavedState)) {
        logError(S, "fmi3SerializeFMUState: size = %zu, expected %zu.", size, sizeof(SavedState));
        CALL(Error);
    }
    memcpy(serializedState, FMUState, sizeof(SavedState));
    END_FUNCTION();
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState *FMUState) {
    BEGIN_FUNCTION(AnyState);
    ASSERT_NOT_NULL(serializedState);
    ASSERT_NOT_NULL(FMUState);
    if (size != sizeof(SavedState)) {
        logError(S, "fmi3DeserializeFMUState: size = %zu, expected %zu (a state of another FMU?).", size,
                 sizeof(SavedState));
        CALL(Error);
    }
    SavedState saved;
    memcpy(&saved, serializedState, sizeof(SavedState));
    if (strncmp(saved.token, INSTANTIATION_TOKEN, sizeof(saved.token)) != 0) {
        logError(S, "The serialized FMU state belongs to another FMU.");
        CALL(Error);
    }
    if (!*FMUState) *FMUState = malloc(sizeof(SavedState));
    if (!*FMUState) {
        logError(S, "Out of memory.");
        CALL(Error);
    }
    memcpy(*FMUState, &saved, sizeof(SavedState));
    END_FUNCTION();
}

/* ---------------------------------------------- partial derivatives, configuration */

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    UNUSED(unknowns); UNUSED(nUnknowns); UNUSED(knowns); UNUSED(nKnowns); UNUSED(seed); UNUSED(nSeed);
    UNUSED(sensitivity); UNUSED(nSensitivity);
    NOT_IMPLEMENTED(GetDirectionalDerivative);
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    UNUSED(unknowns); UNUSED(nUnknowns); UNUSED(knowns); UNUSED(nKnowns); UNUSED(seed); UNUSED(nSeed);
    UNUSED(sensitivity); UNUSED(nSensitivity);
    NOT_IMPLEMENTED(GetAdjointDerivative);
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) {
    BEGIN_FUNCTION(EnterConfigurationMode);
    S->state = ConfigurationMode;
    END_FUNCTION();
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) {
    BEGIN_FUNCTION(ExitConfigurationMode);
    S->state = Instantiated;
    END_FUNCTION();
}

/* ------------------------------------------------------- clocks, Model Exchange */

fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, fmi3Float64 intervals[],
                                  fmi3IntervalQualifier qualifiers[]) {
    UNUSED(valueReferences); UNUSED(nValueReferences); UNUSED(intervals); UNUSED(qualifiers);
    NOT_IMPLEMENTED(GetIntervalDecimal);
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, fmi3UInt64 intervalCounters[], fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[]) {
    UNUSED(valueReferences); UNUSED(nValueReferences); UNUSED(intervalCounters); UNUSED(resolutions);
    UNUSED(qualifiers);
    NOT_IMPLEMENTED(GetIntervalFraction);
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Float64 shifts[]) {
    UNUSED(valueReferences); UNUSED(nValueReferences); UNUSED(shifts);
    NOT_IMPLEMENTED(GetShiftDecimal);
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, fmi3UInt64 shiftCounters[], fmi3UInt64 resolutions[]) {
    UNUSED(valueReferences); UNUSED(nValueReferences); UNUSED(shiftCounters); UNUSED(resolutions);
    NOT_IMPLEMENTED(GetShiftFraction);
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, const fmi3Float64 intervals[]) {
    UNUSED(valueReferences); UNUSED(nValueReferences); UNUSED(intervals);
    NOT_IMPLEMENTED(SetIntervalDecimal);
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, const fmi3UInt64 intervalCounters[],
                                   const fmi3UInt64 resolutions[]) {
    UNUSED(valueReferences); UNUSED(nValueReferences); UNUSED(intervalCounters); UNUSED(resolutions);
    NOT_IMPLEMENTED(SetIntervalFraction);
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Float64 shifts[]) {
    UNUSED(valueReferences); UNUSED(nValueReferences); UNUSED(shifts);
    NOT_IMPLEMENTED(SetShiftDecimal);
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, const fmi3UInt64 shiftCounters[],
                                const fmi3UInt64 resolutions[]) {
    UNUSED(valueReferences); UNUSED(nValueReferences); UNUSED(shiftCounters); UNUSED(resolutions);
    NOT_IMPLEMENTED(SetShiftFraction);
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) {
    NOT_IMPLEMENTED(EvaluateDiscreteStates);
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime) {
    UNUSED(discreteStatesNeedUpdate); UNUSED(terminateSimulation); UNUSED(nominalsOfContinuousStatesChanged);
    UNUSED(valuesOfContinuousStatesChanged); UNUSED(nextEventTimeDefined); UNUSED(nextEventTime);
    NOT_IMPLEMENTED(UpdateDiscreteStates);
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    NOT_IMPLEMENTED(EnterContinuousTimeMode);
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation) {
    UNUSED(noSetFMUStatePriorToCurrentPoint); UNUSED(enterEventMode); UNUSED(terminateSimulation);
    NOT_IMPLEMENTED(CompletedIntegratorStep);
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    UNUSED(time);
    NOT_IMPLEMENTED(SetTime);
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[],
                                   size_t nContinuousStates) {
    UNUSED(continuousStates); UNUSED(nContinuousStates);
    NOT_IMPLEMENTED(SetContinuousStates);
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[],
                                             size_t nContinuousStates) {
    UNUSED(derivatives); UNUSED(nContinuousStates);
    NOT_IMPLEMENTED(GetContinuousStateDerivatives);
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[], size_t nEventIndicators) {
    UNUSED(eventIndicators); UNUSED(nEventIndicators);
    NOT_IMPLEMENTED(GetEventIndicators);
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[], size_t nContinuousStates) {
    UNUSED(continuousStates); UNUSED(nContinuousStates);
    NOT_IMPLEMENTED(GetContinuousStates);
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[],
                                             size_t nContinuousStates) {
    UNUSED(nominals); UNUSED(nContinuousStates);
    NOT_IMPLEMENTED(GetNominalsOfContinuousStates);
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators) {
    UNUSED(nEventIndicators);
    NOT_IMPLEMENTED(GetNumberOfEventIndicators);
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates) {
    UNUSED(nContinuousStates);
    NOT_IMPLEMENTED(GetNumberOfContinuousStates);
}

/* --------------------------------------------------------------- co-simulation */

fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    BEGIN_FUNCTION(EnterStepMode);
    S->state = StepMode;
    END_FUNCTION();
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[],
                                    size_t nValues) {
    UNUSED(valueReferences); UNUSED(nValueReferences); UNUSED(orders); UNUSED(values); UNUSED(nValues);
    NOT_IMPLEMENTED(GetOutputDerivatives);
}

/* one communication step: the inputs set before it are the pin's motion at its END, t + h (model.c) */
fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint,
                      fmi3Float64 communicationStepSize, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn,
                      fmi3Float64 *lastSuccessfulTime) {
    UNUSED(noSetFMUStatePriorToCurrentPoint);
    BEGIN_FUNCTION(DoStep);
    ASSERT_NOT_NULL(eventHandlingNeeded);
    ASSERT_NOT_NULL(terminateSimulation);
    ASSERT_NOT_NULL(earlyReturn);
    ASSERT_NOT_NULL(lastSuccessfulTime);
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = fmi3False;
    *lastSuccessfulTime = S->time;
    if (!isClose(currentCommunicationPoint, S->nextCommunicationPoint)) {
        logError(S, "Expected currentCommunicationPoint = %.16g but was %.16g.", S->nextCommunicationPoint,
                 currentCommunicationPoint);
        CALL(Error);
    }
    if (!(communicationStepSize > 0.0) || !isfinite(communicationStepSize)) {
        logError(S, "Communication step size must be > 0 but was %.16g.", communicationStepSize);
        CALL(Error);
    }
    const double next = currentCommunicationPoint + communicationStepSize;
    if (next > S->stopTime && !isClose(next, S->stopTime)) {
        logError(S, "At %.16g s a step of %.16g s was requested but the stop time is %.16g s.",
                 currentCommunicationPoint, communicationStepSize, S->stopTime);
        CALL(Error);
    }
    S->time = next;  /* the outputs' time, also for the messages of the step */
    CALL(doModelStep(S, communicationStepSize));
    S->nextCommunicationPoint = next;
    *lastSuccessfulTime = next;
    END_FUNCTION();
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime) {
    UNUSED(clockReference); UNUSED(activationTime);
    NOT_IMPLEMENTED(ActivateModelPartition);
}
