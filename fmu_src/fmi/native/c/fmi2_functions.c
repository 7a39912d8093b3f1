/* The FMI 2.0 API of the native bushing FMU (co-simulation and model exchange), on top of
 * the instance (bushing_instance.h, instance_*.c). Compiled after it (see bushing_fmu.h). */
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

typedef struct {
    bw_instance core;
    fmi2CallbackFunctions callbacks;
    char *name;
} fmi2_bushing;

/* A message for the host's logger (bw_log decided it is wanted). FMI 2 treats the message as a
   printf format: a literal percent sign is doubled. */
static void bw_fmi2_log(void *fmi_instance, bw_status status, const char *category, const char *message) {
    fmi2_bushing *c = (fmi2_bushing *)fmi_instance;
    char escaped[2 * BW_MESSAGE];
    size_t i, k = 0;
    for (i = 0; message[i] && k + 2 < sizeof escaped; i++) {
        escaped[k++] = message[i];
        if (message[i] == '%') escaped[k++] = '%';
    }
    escaped[k] = '\0';
    c->callbacks.logger(c->callbacks.componentEnvironment, c->name, (fmi2Status)status, category, escaped);
}

static fmi2Status bw_fmi2_status(bw_status status) { return (fmi2Status)status; }

#define BW_INSTANCE(c) ((fmi2_bushing *)(c))
#define BW_NOT_NULL(c)                                                                                              \
    do {                                                                                                           \
        if (!(c)) return fmi2Error;                                                                                \
    } while (0)

static fmi2Status bw_fmi2_unsupported(fmi2Component c, const char *function) {
    BW_NOT_NULL(c);
    bw_log(&BW_INSTANCE(c)->core, BW_ERROR, "logStatusError", "%s is not supported by this FMU", function);
    return fmi2Error;
}

/* ------------------------------------------------------------------------------- common */

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    BW_NOT_NULL(c);
    if (nCategories > 0 && !categories) return fmi2Error;
    return bw_fmi2_status(bw_set_debug_logging(&BW_INSTANCE(c)->core, loggingOn, nCategories, categories));
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    fmi2_bushing *b;
    size_t length;
    (void)fmuResourceLocation;
    (void)visible;
    if (!functions || !functions->allocateMemory || !functions->freeMemory) return NULL;
    if (!instanceName || !instanceName[0]) {
        if (functions->logger) {
            functions->logger(functions->componentEnvironment, "?", fmi2Error, "logStatusError",
                              "fmi2Instantiate: the instance needs a name");
        }
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, BW_INSTANTIATION_TOKEN) != 0) {
        if (functions->logger) {
            functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError",
                              "fmi2Instantiate: the GUID %s is not this FMU's (%s): the modelDescription.xml and the "
                              "binary come from different builds", fmuGUID ? fmuGUID : "(null)", BW_INSTANTIATION_TOKEN);
        }
        return NULL;
    }
    b = (fmi2_bushing *)functions->allocateMemory(1, sizeof(fmi2_bushing));
    if (!b) return NULL;
    memset(b, 0, sizeof *b);
    length = strlen(instanceName) + 1;
    b->name = (char *)functions->allocateMemory(length, 1);
    if (!b->name) {
        functions->freeMemory(b);
        return NULL;
    }
    memcpy(b->name, instanceName, length);
    b->callbacks = *functions;
    bw_initialize(&b->core, fmuType == fmi2ModelExchange, loggingOn, functions->logger ? bw_fmi2_log : NULL, b);
    return b;
}

void fmi2FreeInstance(fmi2Component c) {
    fmi2_bushing *b = BW_INSTANCE(c);
    fmi2CallbackFreeMemory release;
    if (!b) return;
    release = b->callbacks.freeMemory;
    release(b->name);
    release(b);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    (void)toleranceDefined;
    (void)tolerance;
    (void)stopTimeDefined;
    (void)stopTime;
    BW_NOT_NULL(c);
    BW_INSTANCE(c)->core.data.time = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    BW_NOT_NULL(c);
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    BW_NOT_NULL(c);
    return bw_fmi2_status(bw_exit_initialization(&BW_INSTANCE(c)->core));
}

fmi2Status fmi2Terminate(fmi2Component c) {
    BW_NOT_NULL(c);
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) {
    BW_NOT_NULL(c);
    bw_reset(&BW_INSTANCE(c)->core);
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    size_t i;
    BW_NOT_NULL(c);
    if (nvr > 0 && (!vr || !value)) return fmi2Error;
    for (i = 0; i < nvr; i++) {
        bw_status status = bw_get_real(&BW_INSTANCE(c)->core, vr[i], &value[i]);
        if (status != BW_OK) return bw_fmi2_status(status);
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    size_t i;
    BW_NOT_NULL(c);
    if (nvr > 0 && (!vr || !value)) return fmi2Error;
    for (i = 0; i < nvr; i++) {
        bw_status status = bw_set_real(&BW_INSTANCE(c)->core, vr[i], value[i]);
        if (status != BW_OK) return bw_fmi2_status(status);
    }
    return fmi2OK;
}

static fmi2Status bw_fmi2_no_variables(fmi2Component c, size_t nvr, const char *type) {
    BW_NOT_NULL(c);
    if (nvr == 0) return fmi2OK;
    bw_log(&BW_INSTANCE(c)->core, BW_ERROR, "logStatusError", "this FMU has no %s variables", type);
    return fmi2Error;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
    (void)vr;
    (void)value;
    return bw_fmi2_no_variables(c, nvr, "Integer");
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
    (void)vr;
    (void)value;
    return bw_fmi2_no_variables(c, nvr, "Boolean");
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
    (void)vr;
    (void)value;
    return bw_fmi2_no_variables(c, nvr, "String");
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[]) {
    (void)vr;
    (void)value;
    return bw_fmi2_no_variables(c, nvr, "Integer");
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[]) {
    (void)vr;
    (void)value;
    return bw_fmi2_no_variables(c, nvr, "Boolean");
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
    (void)vr;
    (void)value;
    return bw_fmi2_no_variables(c, nvr, "String");
}

/* ------------------------------------------------------------------------------- FMU state */

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    fmi2_bushing *b = BW_INSTANCE(c);
    BW_NOT_NULL(c);
    if (!FMUstate) return fmi2Error;
    if (!*FMUstate) {
        *FMUstate = b->callbacks.allocateMemory(1, sizeof(bw_saved_state));
        if (!*FMUstate) {
            bw_error(&b->core, "%s", "fmi2GetFMUstate: out of memory");
            return fmi2Error;
        }
    }
    bw_save(&b->core, (bw_saved_state *)*FMUstate);
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate) {
    BW_NOT_NULL(c);
    if (!FMUstate) return fmi2Error;
    return bw_fmi2_status(bw_restore(&BW_INSTANCE(c)->core, (const bw_saved_state *)FMUstate));
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    BW_NOT_NULL(c);
    if (FMUstate && *FMUstate) {
        BW_INSTANCE(c)->callbacks.freeMemory(*FMUstate);
        *FMUstate = NULL;
    }
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size) {
    (void)FMUstate;
    BW_NOT_NULL(c);
    if (!size) return fmi2Error;
    *size = bw_serialized_size();
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[], size_t size) {
    BW_NOT_NULL(c);
    if (!FMUstate || !serializedState || size != bw_serialized_size()) {
        bw_error(&BW_INSTANCE(c)->core, "%s", "fmi2SerializeFMUstate: no state, or a buffer of the wrong size");
        return fmi2Error;
    }
    memcpy(serializedState, FMUstate, size);
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate *FMUstate) {
    bw_saved_state check;
    fmi2_bushing *b = BW_INSTANCE(c);
    BW_NOT_NULL(c);
    if (!serializedState || !FMUstate || size != bw_serialized_size()) {
        bw_error(&b->core, "%s", "fmi2DeSerializeFMUstate: the serialized state has the wrong size for this FMU");
        return fmi2Error;
    }
    memcpy(&check, serializedState, size);
    if (check.magic != BW_STATE_MAGIC || check.size != sizeof(bw_saved_state)) {
        bw_error(&b->core, "%s", "fmi2DeSerializeFMUstate: the bytes are not a state of this FMU");
        return fmi2Error;
    }
    if (!*FMUstate) {
        *FMUstate = b->callbacks.allocateMemory(1, sizeof(bw_saved_state));
        if (!*FMUstate) return fmi2Error;
    }
    memcpy(*FMUstate, &check, size);
    return fmi2OK;
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[]) {
    BW_NOT_NULL(c);
    if ((nUnknown && (!vUnknown_ref || !dvUnknown)) || (nKnown && (!vKnown_ref || !dvKnown))) {
        bw_error(&BW_INSTANCE(c)->core, "%s", "fmi2GetDirectionalDerivative: an array argument is NULL");
        return fmi2Error;
    }
    return bw_fmi2_status(bw_directional_derivative(&BW_INSTANCE(c)->core, "fmi2GetDirectionalDerivative",
                                                    vUnknown_ref, nUnknown, vKnown_ref, nKnown, dvKnown, dvUnknown));
}

/* ------------------------------------------------------------------------------- co-simulation */

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    return bw_fmi2_unsupported(c, "fmi2SetRealInputDerivatives");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    return bw_fmi2_unsupported(c, "fmi2GetRealOutputDerivatives");
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    (void)noSetFMUStatePriorToCurrentPoint;
    BW_NOT_NULL(c);
    return bw_fmi2_status(bw_do_step(&BW_INSTANCE(c)->core, currentCommunicationPoint, communicationStepSize));
}

fmi2Status fmi2CancelStep(fmi2Component c) { return bw_fmi2_unsupported(c, "fmi2CancelStep"); }

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)s;
    (void)value;
    return bw_fmi2_unsupported(c, "fmi2GetStatus");
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    BW_NOT_NULL(c);
    if (s == fmi2LastSuccessfulTime && value) {
        *value = BW_INSTANCE(c)->core.data.time;
        return fmi2OK;
    }
    return bw_fmi2_unsupported(c, "fmi2GetRealStatus (other than fmi2LastSuccessfulTime)");
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)s;
    (void)value;
    return bw_fmi2_unsupported(c, "fmi2GetIntegerStatus");
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    BW_NOT_NULL(c);
    if (s == fmi2Terminated && value) {
        *value = fmi2False;
        return fmi2OK;
    }
    return bw_fmi2_unsupported(c, "fmi2GetBooleanStatus (other than fmi2Terminated)");
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)s;
    (void)value;
    return bw_fmi2_unsupported(c, "fmi2GetStringStatus");
}

/* ------------------------------------------------------------------------------- model exchange */

fmi2Status fmi2EnterEventMode(fmi2Component c) {
    BW_NOT_NULL(c);
    return fmi2OK;
}

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *eventInfo) {
    BW_NOT_NULL(c);
    if (!eventInfo) return fmi2Error;
    /* the states change only where a model's update says so (a friction element's reversal); once
       changed they are consistent, so no second iteration is needed */
    eventInfo->newDiscreteStatesNeeded = fmi2False;
    eventInfo->terminateSimulation = fmi2False;
    eventInfo->nominalsOfContinuousStatesChanged = fmi2False;
    eventInfo->valuesOfContinuousStatesChanged = bw_update_discrete_states(&BW_INSTANCE(c)->core, 1) ? fmi2True
                                                                                                   : fmi2False;
    eventInfo->nextEventTimeDefined = fmi2False;
    eventInfo->nextEventTime = 0.0;
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) {
    BW_NOT_NULL(c);
    return fmi2OK;
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint;
    BW_NOT_NULL(c);
    /* a reversal the event indicators did not locate (the velocity's root found on its old side) */
    if (enterEventMode) *enterEventMode = bw_update_discrete_states(&BW_INSTANCE(c)->core, 0) ? fmi2True : fmi2False;
    if (terminateSimulation) *terminateSimulation = fmi2False;
    return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
    BW_NOT_NULL(c);
    BW_INSTANCE(c)->core.data.time = time;
    return fmi2OK;
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
    BW_NOT_NULL(c);
    if (nx > 0 && !x) return fmi2Error;
    return bw_fmi2_status(bw_set_continuous_states(&BW_INSTANCE(c)->core, x, nx));
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx) {
    BW_NOT_NULL(c);
    if (nx > 0 && !derivatives) return fmi2Error;
    return bw_fmi2_status(bw_derivatives(&BW_INSTANCE(c)->core, derivatives, nx));
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real eventIndicators[], size_t ni) {
    BW_NOT_NULL(c);
    if (ni > 0 && !eventIndicators) return fmi2Error;
    return bw_fmi2_status(bw_event_indicators(&BW_INSTANCE(c)->core, eventIndicators, ni));
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
    BW_NOT_NULL(c);
    if (nx > 0 && !x) return fmi2Error;
    return bw_fmi2_status(bw_get_continuous_states(&BW_INSTANCE(c)->core, x, nx));
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[], size_t nx) {
    BW_NOT_NULL(c);
    if (nx != BW_CONTINUOUS_STATES || (nx > 0 && !x_nominal)) {
        bw_log(&BW_INSTANCE(c)->core, BW_ERROR, "logStatusError", "asked for %lu nominals: this FMU has %d continuous "
               "states", (unsigned long)nx, BW_CONTINUOUS_STATES);
        return fmi2Error;
    }
    bw_nominals(x_nominal, nx);
    return fmi2OK;
}
