/* The FMI 3.0 API of the native bushing FMU (co-simulation and model exchange), on top of
 * the instance (bushing_instance.h, instance_*.c), as fmi2_functions.c is for FMI 2.0. Compiled
 * after it (see bushing_fmu.h).
 * Every function of the standard is here; the ones this FMU has no use for (other variable
 * types, clocks, scheduled execution, directional derivatives) return fmi3Error and say so. */
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"

typedef struct {
    bw_instance core;
    fmi3InstanceEnvironment environment;
    fmi3LogMessageCallback log_message;
    char *name;
} fmi3_bushing;

/* A message for the host's logger (bw_log decided it is wanted); FMI 3 messages are plain text. */
static void bw_fmi3_log(void *fmi_instance, bw_status status, const char *category, const char *message) {
    fmi3_bushing *b = (fmi3_bushing *)fmi_instance;
    b->log_message(b->environment, (fmi3Status)status, category, message);
}

#define BW3(instance) ((fmi3_bushing *)(instance))
#define BW3_NOT_NULL(instance)                                                                                     \
    do {                                                                                                           \
        if (!(instance)) return fmi3Error;                                                                         \
    } while (0)

static fmi3Status bw_fmi3_status(bw_status status) { return (fmi3Status)status; }

static fmi3Status bw_fmi3_unsupported(fmi3Instance instance, const char *function) {
    BW3_NOT_NULL(instance);
    bw_log(&BW3(instance)->core, BW_ERROR, "logStatusError", "%s is not supported by this FMU", function);
    return fmi3Error;
}

/* ------------------------------------------------------------------------------- life cycle */

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
    BW3_NOT_NULL(instance);
    if (nCategories > 0 && !categories) return fmi3Error;
    return bw_fmi3_status(bw_set_debug_logging(&BW3(instance)->core, loggingOn, nCategories, categories));
}

static fmi3Instance bw_fmi3_instantiate(fmi3String instanceName, fmi3String instantiationToken, fmi3Boolean loggingOn,
                                        fmi3InstanceEnvironment environment, fmi3LogMessageCallback logMessage,
                                        int model_exchange) {
    fmi3_bushing *b;
    size_t length;
    if (!instanceName || !instanceName[0]) {
        if (logMessage) logMessage(environment, fmi3Error, "logStatusError", "fmi3Instantiate: the instance needs a name");
        return NULL;
    }
    if (!instantiationToken || strcmp(instantiationToken, BW_INSTANTIATION_TOKEN) != 0) {
        if (logMessage) {
            logMessage(environment, fmi3Error, "logStatusError", "fmi3Instantiate: the instantiation token is not this "
                       "FMU's: the modelDescription.xml and the binary come from different builds");
        }
        return NULL;
    }
    b = (fmi3_bushing *)calloc(1, sizeof(fmi3_bushing));
    if (!b) return NULL;
    length = strlen(instanceName) + 1;
    b->name = (char *)malloc(length);
    if (!b->name) {
        free(b);
        return NULL;
    }
    memcpy(b->name, instanceName, length);
    b->environment = environment;
    b->log_message = logMessage;
    bw_initialize(&b->core, model_exchange, loggingOn, logMessage ? bw_fmi3_log : NULL, b);
    return b;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage) {
    (void)resourcePath;
    (void)visible;
    return bw_fmi3_instantiate(instanceName, instantiationToken, loggingOn, instanceEnvironment, logMessage, 1);
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment, fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)resourcePath;
    (void)visible;
    (void)eventModeUsed;        /* no events in co-simulation: the FMU's step never stops early */
    (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables;
    (void)nRequiredIntermediateVariables;
    (void)intermediateUpdate;
    return bw_fmi3_instantiate(instanceName, instantiationToken, loggingOn, instanceEnvironment, logMessage, 0);
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instantiationToken;
    (void)resourcePath;
    (void)visible;
    (void)loggingOn;
    (void)clockUpdate;
    (void)lockPreemption;
    (void)unlockPreemption;
    if (logMessage) {
        logMessage(instanceEnvironment, fmi3Error, "logStatusError", "scheduled execution is not supported by this "
                   "FMU (co-simulation and model exchange are)");
    }
    (void)instanceName;
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance) {
    fmi3_bushing *b = BW3(instance);
    if (!b) return;
    free(b->name);
    free(b);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    (void)toleranceDefined;
    (void)tolerance;
    (void)stopTimeDefined;
    (void)stopTime;
    BW3_NOT_NULL(instance);
    BW3(instance)->core.data.time = startTime;
    return fmi3OK;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    BW3_NOT_NULL(instance);
    return bw_fmi3_status(bw_exit_initialization(&BW3(instance)->core));
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    BW3_NOT_NULL(instance);
    return fmi3OK;
}

fmi3Status fmi3Terminate(fmi3Instance instance) {
    BW3_NOT_NULL(instance);
    return fmi3OK;
}

fmi3Status fmi3Reset(fmi3Instance instance) {
    BW3_NOT_NULL(instance);
    bw_reset(&BW3(instance)->core);
    return fmi3OK;
}

/* ------------------------------------------------------------------------------- variables */

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          fmi3Float64 values[], size_t nValues) {
    size_t i;
    BW3_NOT_NULL(instance);
    if (nValues != nValueReferences || (nValueReferences > 0 && (!valueReferences || !values))) {
        bw_error(&BW3(instance)->core, "%s", "fmi3GetFloat64: every variable of this FMU is a scalar (nValues must equal "
                 "nValueReferences)");
        return fmi3Error;
    }
    for (i = 0; i < nValueReferences; i++) {
        bw_status status = bw_get_real(&BW3(instance)->core, valueReferences[i], &values[i]);
        if (status != BW_OK) return bw_fmi3_status(status);
    }
    return fmi3OK;
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          const fmi3Float64 values[], size_t nValues) {
    size_t i;
    BW3_NOT_NULL(instance);
    if (nValues != nValueReferences || (nValueReferences > 0 && (!valueReferences || !values))) {
        bw_error(&BW3(instance)->core, "%s", "fmi3SetFloat64: every variable of this FMU is a scalar (nValues must equal "
                 "nValueReferences)");
        return fmi3Error;
    }
    for (i = 0; i < nValueReferences; i++) {
        bw_status status = bw_set_real(&BW3(instance)->core, valueReferences[i], values[i]);
        if (status != BW_OK) return bw_fmi3_status(status);
    }
    return fmi3OK;
}

static fmi3Status bw_fmi3_none(fmi3Instance instance, size_t nValueReferences, const char *type) {
    BW3_NOT_NULL(instance);
    if (nValueReferences == 0) return fmi3OK;
    bw_log(&BW3(instance)->core, BW_ERROR, "logStatusError", "this FMU has no %s variables", type);
    return fmi3Error;
}

/* The other variable types: this FMU has none. */
#define BW3_NO_TYPE(getter, setter, ctype, name)                                                                   \
    fmi3Status getter(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,    \
                      ctype values[], size_t nValues) {                                                            \
        (void)valueReferences;                                                                                     \
        (void)values;                                                                                              \
        (void)nValues;                                                                                             \
        return bw_fmi3_none(instance, nValueReferences, name);                                                     \
    }                                                                                                              \
    fmi3Status setter(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,    \
                      const ctype values[], size_t nValues) {                                                      \
        (void)valueReferences;                                                                                     \
        (void)values;                                                                                              \
        (void)nValues;                                                                                             \
        return bw_fmi3_none(instance, nValueReferences, name);                                                     \
    }

BW3_NO_TYPE(fmi3GetFloat32, fmi3SetFloat32, fmi3Float32, "Float32")
BW3_NO_TYPE(fmi3GetInt8, fmi3SetInt8, fmi3Int8, "Int8")
BW3_NO_TYPE(fmi3GetUInt8, fmi3SetUInt8, fmi3UInt8, "UInt8")
BW3_NO_TYPE(fmi3GetInt16, fmi3SetInt16, fmi3Int16, "Int16")
BW3_NO_TYPE(fmi3GetUInt16, fmi3SetUInt16, fmi3UInt16, "UInt16")
BW3_NO_TYPE(fmi3GetInt32, fmi3SetInt32, fmi3Int32, "Int32")
BW3_NO_TYPE(fmi3GetUInt32, fmi3SetUInt32, fmi3UInt32, "UInt32")
BW3_NO_TYPE(fmi3GetInt64, fmi3SetInt64, fmi3Int64, "Int64")
BW3_NO_TYPE(fmi3GetUInt64, fmi3SetUInt64, fmi3UInt64, "UInt64")
BW3_NO_TYPE(fmi3GetBoolean, fmi3SetBoolean, fmi3Boolean, "Boolean")
BW3_NO_TYPE(fmi3GetString, fmi3SetString, fmi3String, "String")

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         size_t valueSizes[], fmi3Binary values[], size_t nValues) {
    (void)valueReferences;
    (void)valueSizes;
    (void)values;
    (void)nValues;
    return bw_fmi3_none(instance, nValueReferences, "Binary");
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         const size_t valueSizes[], const fmi3Binary values[], size_t nValues) {
    (void)valueReferences;
    (void)valueSizes;
    (void)values;
    (void)nValues;
    return bw_fmi3_none(instance, nValueReferences, "Binary");
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        fmi3Clock values[]) {
    (void)valueReferences;
    (void)values;
    return bw_fmi3_none(instance, nValueReferences, "Clock");
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        const fmi3Clock values[]) {
    (void)valueReferences;
    (void)values;
    return bw_fmi3_none(instance, nValueReferences, "Clock");
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference,
                                               size_t *nDependencies) {
    (void)valueReference;
    (void)nDependencies;
    return bw_fmi3_unsupported(instance, "fmi3GetNumberOfVariableDependencies (the modelDescription declares them)");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies) {
    (void)dependent;
    (void)elementIndicesOfDependent;
    (void)independents;
    (void)elementIndicesOfIndependents;
    (void)dependencyKinds;
    (void)nDependencies;
    return bw_fmi3_unsupported(instance, "fmi3GetVariableDependencies (the modelDescription declares them)");
}

/* ------------------------------------------------------------------------------- FMU state */

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    BW3_NOT_NULL(instance);
    if (!FMUState) return fmi3Error;
    if (!*FMUState) {
        *FMUState = calloc(1, sizeof(bw_saved_state));
        if (!*FMUState) {
            bw_error(&BW3(instance)->core, "%s", "fmi3GetFMUState: out of memory");
            return fmi3Error;
        }
    }
    bw_save(&BW3(instance)->core, (bw_saved_state *)*FMUState);
    return fmi3OK;
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState) {
    BW3_NOT_NULL(instance);
    if (!FMUState) return fmi3Error;
    return bw_fmi3_status(bw_restore(&BW3(instance)->core, (const bw_saved_state *)FMUState));
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    BW3_NOT_NULL(instance);
    if (FMUState && *FMUState) {
        free(*FMUState);
        *FMUState = NULL;
    }
    return fmi3OK;
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t *size) {
    (void)FMUState;
    BW3_NOT_NULL(instance);
    if (!size) return fmi3Error;
    *size = bw_serialized_size();
    return fmi3OK;
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[],
                                 size_t size) {
    BW3_NOT_NULL(instance);
    if (!FMUState || !serializedState || size != bw_serialized_size()) {
        bw_error(&BW3(instance)->core, "%s", "fmi3SerializeFMUState: no state, or a buffer of the wrong size");
        return fmi3Error;
    }
    memcpy(serializedState, FMUState, size);
    return fmi3OK;
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState *FMUState) {
    bw_saved_state check;
    BW3_NOT_NULL(instance);
    if (!serializedState || !FMUState || size != bw_serialized_size()) {
        bw_error(&BW3(instance)->core, "%s", "fmi3DeserializeFMUState: the serialized state has the wrong size for this FMU");
        return fmi3Error;
    }
    memcpy(&check, serializedState, size);
    if (check.magic != BW_STATE_MAGIC || check.size != sizeof(bw_saved_state)) {
        bw_error(&BW3(instance)->core, "%s", "fmi3DeserializeFMUState: the bytes are not a state of this FMU");
        return fmi3Error;
    }
    if (!*FMUState) {
        *FMUState = calloc(1, sizeof(bw_saved_state));
        if (!*FMUState) return fmi3Error;
    }
    memcpy(*FMUState, &check, size);
    return fmi3OK;
}

/* ------------------------------------------------------------------------------- derivatives */

/* The arguments of fmi3Get{Directional,Adjoint}Derivative: every variable is a scalar, so the
   seed has one value per known (adjoint: per unknown) and the sensitivity one per unknown
   (adjoint: per known). */
static int bw3_derivative_arguments(fmi3Instance instance, const char *function, const fmi3ValueReference unknowns[],
                                    size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns,
                                    const fmi3Float64 seed[], size_t nSeed, size_t seeds, fmi3Float64 sensitivity[],
                                    size_t nSensitivity, size_t sensitivities) {
    if ((nUnknowns && !unknowns) || (nKnowns && !knowns) || (nSeed && !seed) || (nSensitivity && !sensitivity)) {
        bw_log(&BW3(instance)->core, BW_ERROR, "logStatusError", "%s: an array argument is NULL", function);
        return 0;
    }
    if (nSeed != seeds || nSensitivity != sensitivities) {
        bw_log(&BW3(instance)->core, BW_ERROR, "logStatusError", "%s: nSeed = %lu and nSensitivity = %lu must be %lu "
               "and %lu (every variable of this FMU is a scalar)", function, (unsigned long)nSeed,
               (unsigned long)nSensitivity, (unsigned long)seeds, (unsigned long)sensitivities);
        return 0;
    }
    return 1;
}

/* fmi3GetAdjointDerivative (FMI 3 only, so here rather than in instance_derivatives.c):
   sensitivity = J^T * seed, one directional derivative per known (the column of J that the
   known's entry of J^T * seed needs; an axis's tangent, or a coupled group's), so it equals the
   transposed Jacobian of bw_directional_derivative to rounding. */
static bw_status bw_adjoint_derivative(bw_instance *inst, const char *function, const unsigned int unknowns[],
                                       size_t n_unknowns, const unsigned int knowns[], size_t n_knowns,
                                       const double seed[], double sensitivity[]) {
    double column[BW_VARIABLES];
    const double one = 1.0;
    size_t i, j;
    bw_status status = bw_check_derivative_variables(inst, function, unknowns, n_unknowns, knowns, n_knowns);
    if (status != BW_OK) return status;
    if (n_unknowns > BW_VARIABLES) {
        bw_log(inst, BW_ERROR, "logStatusError", "%s: %lu unknowns: this FMU has %d variables", function,
               (unsigned long)n_unknowns, BW_VARIABLES);
        return BW_ERROR;
    }
    for (j = 0; j < n_knowns; j++) {
        double sum = 0.0;
        status = bw_directional_derivative(inst, function, unknowns, n_unknowns, &knowns[j], 1, &one, column);
        if (status != BW_OK) return status;
        for (i = 0; i < n_unknowns; i++) sum += seed[i] * column[i];
        sensitivity[j] = sum;
    }
    return BW_OK;
}

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    const char *function = "fmi3GetDirectionalDerivative";
    BW3_NOT_NULL(instance);
    if (!bw3_derivative_arguments(instance, function, unknowns, nUnknowns, knowns, nKnowns, seed, nSeed, nKnowns,
                                  sensitivity, nSensitivity, nUnknowns)) {
        return fmi3Error;
    }
    return bw_fmi3_status(bw_directional_derivative(&BW3(instance)->core, function, unknowns, nUnknowns, knowns,
                                                    nKnowns, seed, sensitivity));
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    const char *function = "fmi3GetAdjointDerivative";
    BW3_NOT_NULL(instance);
    if (!bw3_derivative_arguments(instance, function, unknowns, nUnknowns, knowns, nKnowns, seed, nSeed, nUnknowns,
                                  sensitivity, nSensitivity, nKnowns)) {
        return fmi3Error;
    }
    return bw_fmi3_status(bw_adjoint_derivative(&BW3(instance)->core, function, unknowns, nUnknowns, knowns, nKnowns,
                                                seed, sensitivity));
}

/* ------------------------------------------------------------------------------- not supported */

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) {
    return bw_fmi3_unsupported(instance, "fmi3EnterConfigurationMode (no structural parameters)");
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) {
    return bw_fmi3_unsupported(instance, "fmi3ExitConfigurationMode (no structural parameters)");
}

fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[]) {
    (void)valueReferences;
    (void)intervals;
    (void)qualifiers;
    return bw_fmi3_none(instance, nValueReferences, "Clock");
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[]) {
    (void)valueReferences;
    (void)counters;
    (void)resolutions;
    (void)qualifiers;
    return bw_fmi3_none(instance, nValueReferences, "Clock");
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Float64 shifts[]) {
    (void)valueReferences;
    (void)shifts;
    return bw_fmi3_none(instance, nValueReferences, "Clock");
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[]) {
    (void)valueReferences;
    (void)counters;
    (void)resolutions;
    return bw_fmi3_none(instance, nValueReferences, "Clock");
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, const fmi3Float64 intervals[]) {
    (void)valueReferences;
    (void)intervals;
    return bw_fmi3_none(instance, nValueReferences, "Clock");
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, const fmi3UInt64 counters[],
                                   const fmi3UInt64 resolutions[]) {
    (void)valueReferences;
    (void)counters;
    (void)resolutions;
    return bw_fmi3_none(instance, nValueReferences, "Clock");
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Float64 shifts[]) {
    (void)valueReferences;
    (void)shifts;
    return bw_fmi3_none(instance, nValueReferences, "Clock");
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]) {
    (void)valueReferences;
    (void)counters;
    (void)resolutions;
    return bw_fmi3_none(instance, nValueReferences, "Clock");
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) {
    BW3_NOT_NULL(instance);
    return fmi3OK;   /* no discrete states */
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime) {
    (void)clockReference;
    (void)activationTime;
    return bw_fmi3_unsupported(instance, "fmi3ActivateModelPartition (scheduled execution)");
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[],
                                    size_t nValues) {
    (void)valueReferences;
    (void)nValueReferences;
    (void)orders;
    (void)values;
    (void)nValues;
    return bw_fmi3_unsupported(instance, "fmi3GetOutputDerivatives");
}

/* ------------------------------------------------------------------------------- model exchange */

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime) {
    int changed;
    BW3_NOT_NULL(instance);
    /* the states change only where a model's update says so (a friction element's reversal); once
       changed they are consistent, so no second iteration is needed */
    changed = bw_update_discrete_states(&BW3(instance)->core, 1);
    if (discreteStatesNeedUpdate) *discreteStatesNeedUpdate = fmi3False;
    if (terminateSimulation) *terminateSimulation = fmi3False;
    if (nominalsOfContinuousStatesChanged) *nominalsOfContinuousStatesChanged = fmi3False;
    if (valuesOfContinuousStatesChanged) *valuesOfContinuousStatesChanged = changed ? fmi3True : fmi3False;
    if (nextEventTimeDefined) *nextEventTimeDefined = fmi3False;
    if (nextEventTime) *nextEventTime = 0.0;
    return fmi3OK;
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    BW3_NOT_NULL(instance);
    return fmi3OK;
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint;
    BW3_NOT_NULL(instance);
    /* a reversal the event indicators did not locate (the velocity's root found on its old side) */
    if (enterEventMode) *enterEventMode = bw_update_discrete_states(&BW3(instance)->core, 0) ? fmi3True : fmi3False;
    if (terminateSimulation) *terminateSimulation = fmi3False;
    return fmi3OK;
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    BW3_NOT_NULL(instance);
    BW3(instance)->core.data.time = time;
    return fmi3OK;
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[],
                                   size_t nContinuousStates) {
    BW3_NOT_NULL(instance);
    if (nContinuousStates > 0 && !continuousStates) return fmi3Error;
    return bw_fmi3_status(bw_set_continuous_states(&BW3(instance)->core, continuousStates, nContinuousStates));
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[],
                                             size_t nContinuousStates) {
    BW3_NOT_NULL(instance);
    if (nContinuousStates > 0 && !derivatives) return fmi3Error;
    return bw_fmi3_status(bw_derivatives(&BW3(instance)->core, derivatives, nContinuousStates));
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[], size_t nEventIndicators) {
    BW3_NOT_NULL(instance);
    if (nEventIndicators > 0 && !eventIndicators) return fmi3Error;
    return bw_fmi3_status(bw_event_indicators(&BW3(instance)->core, eventIndicators, nEventIndicators));
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[], size_t nContinuousStates) {
    BW3_NOT_NULL(instance);
    if (nContinuousStates > 0 && !continuousStates) return fmi3Error;
    return bw_fmi3_status(bw_get_continuous_states(&BW3(instance)->core, continuousStates, nContinuousStates));
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t nContinuousStates) {
    BW3_NOT_NULL(instance);
    if (nContinuousStates != BW_CONTINUOUS_STATES || (nContinuousStates > 0 && !nominals)) {
        bw_log(&BW3(instance)->core, BW_ERROR, "logStatusError", "asked for %lu nominals: this FMU has %d continuous "
               "states", (unsigned long)nContinuousStates, BW_CONTINUOUS_STATES);
        return fmi3Error;
    }
    bw_nominals(nominals, nContinuousStates);
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators) {
    BW3_NOT_NULL(instance);
    if (!nEventIndicators) return fmi3Error;
    *nEventIndicators = BW_EVENT_INDICATORS;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates) {
    BW3_NOT_NULL(instance);
    if (!nContinuousStates) return fmi3Error;
    *nContinuousStates = BW_CONTINUOUS_STATES;
    return fmi3OK;
}

/* ------------------------------------------------------------------------------- co-simulation */

fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    BW3_NOT_NULL(instance);
    return fmi3OK;
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    bw_status status;
    (void)noSetFMUStatePriorToCurrentPoint;
    BW3_NOT_NULL(instance);
    status = bw_do_step(&BW3(instance)->core, currentCommunicationPoint, communicationStepSize);
    if (eventHandlingNeeded) *eventHandlingNeeded = fmi3False;
    if (terminateSimulation) *terminateSimulation = fmi3False;
    if (earlyReturn) *earlyReturn = fmi3False;
    if (lastSuccessfulTime) {
        *lastSuccessfulTime = status == BW_OK ? currentCommunicationPoint + communicationStepSize
                                              : currentCommunicationPoint;
    }
    return bw_fmi3_status(status);
}
