/* A C master that puts a native bushing FMU (FMI 2.0, Table 5 defaults) through what it must
 * survive, for tests/fmu_src/fmi/test_native_fmu.py, which builds it and the FMU with
 * -fsanitize=address,undefined: bad inputs, FMU state save/restore and serialization, and 1000
 * instantiate/free cycles. Any unexpected status, any restored run that differs by a bit, and
 * any sanitizer report fails it (exit status != 0); it ends with "all checks passed".
 *
 * usage: native_checks FMU_SO GUID REF_X REF_V REF_F REF_C1 */
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#define LOAD(name)                                                                                                 \
    name##TYPE *name = (name##TYPE *)dlsym(fmu, #name);                                                            \
    if (!name) {                                                                                                   \
        fprintf(stderr, "missing %s\n", #name);                                                                    \
        return 3;                                                                                                  \
    }
#define EXPECT(call, wanted)                                                                                       \
    do {                                                                                                           \
        fmi2Status s_ = (call);                                                                                    \
        if (s_ != (wanted)) {                                                                                      \
            fprintf(stderr, "line %d: %s returned %d, expected %d\n", __LINE__, #call, s_, wanted);                \
            return 4;                                                                                              \
        }                                                                                                          \
    } while (0)

static int messages = 0;

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
    (void)env;
    (void)name;
    (void)status;
    (void)category;
    (void)message;
    messages++;
}

int main(int argc, char **argv) {
    void *fmu;
    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    fmi2ValueReference x_ref, v_ref, f_ref, c1_ref, xv[2], bad_ref = 999999;
    const char *guid;
    double pi = acos(-1.0), h = 1e-3;
    int k, cycle;
    if (argc != 7) {
        fprintf(stderr, "usage: native_checks FMU_SO GUID REF_X REF_V REF_F REF_C1\n");
        return 1;
    }
    fmu = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!fmu) {
        fprintf(stderr, "%s\n", dlerror());
        return 2;
    }
    guid = argv[2];
    x_ref = (fmi2ValueReference)atoi(argv[3]);
    v_ref = (fmi2ValueReference)atoi(argv[4]);
    f_ref = (fmi2ValueReference)atoi(argv[5]);
    c1_ref = (fmi2ValueReference)atoi(argv[6]);
    xv[0] = x_ref;
    xv[1] = v_ref;
    {
        LOAD(fmi2Instantiate)
        LOAD(fmi2FreeInstance)
        LOAD(fmi2SetupExperiment)
        LOAD(fmi2EnterInitializationMode)
        LOAD(fmi2ExitInitializationMode)
        LOAD(fmi2SetReal)
        LOAD(fmi2GetReal)
        LOAD(fmi2DoStep)
        LOAD(fmi2Reset)
        LOAD(fmi2GetFMUstate)
        LOAD(fmi2SetFMUstate)
        LOAD(fmi2FreeFMUstate)
        LOAD(fmi2SerializedFMUstateSize)
        LOAD(fmi2SerializeFMUstate)
        LOAD(fmi2DeSerializeFMUstate)
        LOAD(fmi2GetDerivatives)
        LOAD(fmi2GetContinuousStates)
        LOAD(fmi2SetContinuousStates)
        LOAD(fmi2GetEventIndicators)
        LOAD(fmi2GetDirectionalDerivative)
        fmi2Component c;
        fmi2FMUstate saved = NULL, restored = NULL;
        double inputs[2], force, first[50], again[50], nan_value = NAN, values[8], seed[2] = {1.0, 0.5}, dF[2];
        size_t size;
        fmi2Byte *bytes;

        /* an instance that is not this FMU's, and calls without an instance */
        if (fmi2Instantiate("wrong", fmi2CoSimulation, "{not-the-guid}", "", &callbacks, 0, 0) != NULL) return 5;
        EXPECT(fmi2DoStep(NULL, 0.0, h, 1), fmi2Error);
        EXPECT(fmi2SetReal(NULL, &x_ref, 1, &force), fmi2Error);

        /* 1000 instantiate/free cycles, each one stepping */
        for (cycle = 0; cycle < 1000; cycle++) {
            c = fmi2Instantiate("cycle", cycle % 2 ? fmi2ModelExchange : fmi2CoSimulation, guid, "", &callbacks, 0,
                                cycle % 3 == 0);
            if (!c) return 6;
            EXPECT(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), fmi2OK);
            EXPECT(fmi2EnterInitializationMode(c), fmi2OK);
            EXPECT(fmi2ExitInitializationMode(c), fmi2OK);
            inputs[0] = 1e-3;
            inputs[1] = 0.01;
            EXPECT(fmi2SetReal(c, xv, 2, inputs), fmi2OK);
            if (cycle % 2 == 0) EXPECT(fmi2DoStep(c, 0.0, h, 1), fmi2OK);
            EXPECT(fmi2GetReal(c, &f_ref, 1, &force), fmi2OK);
            if (!isfinite(force)) return 7;
            fmi2FreeInstance(c);
        }

        c = fmi2Instantiate("checks", fmi2CoSimulation, guid, "", &callbacks, 0, 0);
        if (!c) return 6;
        /* an invalid start value: an error at the exit of initialization, then reset and start again */
        values[0] = -1.0;
        EXPECT(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), fmi2OK);
        EXPECT(fmi2EnterInitializationMode(c), fmi2OK);
        EXPECT(fmi2SetReal(c, &c1_ref, 1, values), fmi2OK);
        EXPECT(fmi2ExitInitializationMode(c), fmi2Error);
        EXPECT(fmi2Reset(c), fmi2OK);
        EXPECT(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), fmi2OK);
        EXPECT(fmi2EnterInitializationMode(c), fmi2OK);
        EXPECT(fmi2ExitInitializationMode(c), fmi2OK);

        /* bad inputs: refused, nothing lost */
        EXPECT(fmi2SetReal(c, &bad_ref, 1, values), fmi2Error);
        EXPECT(fmi2GetReal(c, &bad_ref, 1, values), fmi2Error);
        EXPECT(fmi2SetReal(c, &f_ref, 1, values), fmi2Error);          /* an output cannot be set */
        EXPECT(fmi2DoStep(c, 0.0, 0.0, 1), fmi2Discard);
        EXPECT(fmi2DoStep(c, 0.0, -h, 1), fmi2Discard);
        EXPECT(fmi2DoStep(c, 0.0, nan_value, 1), fmi2Discard);
        EXPECT(fmi2SetReal(c, &x_ref, 1, &nan_value), fmi2OK);
        EXPECT(fmi2DoStep(c, 0.0, h, 1), fmi2Discard);
        EXPECT(fmi2GetReal(c, &f_ref, 1, &force), fmi2OK);
        if (!isfinite(force)) return 8;
        inputs[0] = 2.0;            /* millimetres entered as metres: a jump of 2 m */
        inputs[1] = 0.0;
        EXPECT(fmi2SetReal(c, xv, 2, inputs), fmi2OK);
        EXPECT(fmi2DoStep(c, 0.0, h, 1), fmi2Discard);
        values[0] = -1.0;           /* an invalid parameter during the run */
        EXPECT(fmi2SetReal(c, &c1_ref, 1, values), fmi2OK);
        inputs[0] = 0.0;
        EXPECT(fmi2SetReal(c, xv, 2, inputs), fmi2OK);
        EXPECT(fmi2DoStep(c, 0.0, h, 1), fmi2Discard);
        values[0] = 1.485;
        EXPECT(fmi2SetReal(c, &c1_ref, 1, values), fmi2OK);
        EXPECT(fmi2GetDerivatives(c, values, 3), fmi2Error);           /* a co-simulation instance has 4 */
        EXPECT(fmi2GetEventIndicators(c, values, 9), fmi2Error);
        EXPECT(fmi2GetContinuousStates(c, values, 4), fmi2OK);
        EXPECT(fmi2SetContinuousStates(c, values, 5), fmi2Error);

        /* state: save, step, restore, step again: the same bits; and through serialization */
        for (k = 0; k < 50; k++) {
            inputs[0] = 2e-3 * sin(2 * pi * 10 * k * h);
            inputs[1] = 2e-3 * 2 * pi * 10 * cos(2 * pi * 10 * k * h);
            EXPECT(fmi2SetReal(c, xv, 2, inputs), fmi2OK);
            EXPECT(fmi2DoStep(c, k * h, h, 1), fmi2OK);
        }
        EXPECT(fmi2GetFMUstate(c, &saved), fmi2OK);
        EXPECT(fmi2SerializedFMUstateSize(c, saved, &size), fmi2OK);
        bytes = (fmi2Byte *)malloc(size);
        if (!bytes) return 9;
        EXPECT(fmi2SerializeFMUstate(c, saved, bytes, size), fmi2OK);
        EXPECT(fmi2SerializeFMUstate(c, saved, bytes, size - 1), fmi2Error);
        for (k = 50; k < 100; k++) {
            inputs[0] = 2e-3 * sin(2 * pi * 10 * k * h);
            inputs[1] = 2e-3 * 2 * pi * 10 * cos(2 * pi * 10 * k * h);
            EXPECT(fmi2SetReal(c, xv, 2, inputs), fmi2OK);
            EXPECT(fmi2DoStep(c, k * h, h, 1), fmi2OK);
            EXPECT(fmi2GetReal(c, &f_ref, 1, &first[k - 50]), fmi2OK);
        }
        EXPECT(fmi2SetFMUstate(c, saved), fmi2OK);
        for (cycle = 0; cycle < 2; cycle++) {
            for (k = 50; k < 100; k++) {
                inputs[0] = 2e-3 * sin(2 * pi * 10 * k * h);
                inputs[1] = 2e-3 * 2 * pi * 10 * cos(2 * pi * 10 * k * h);
                EXPECT(fmi2SetReal(c, xv, 2, inputs), fmi2OK);
                EXPECT(fmi2DoStep(c, k * h, h, 1), fmi2OK);
                EXPECT(fmi2GetReal(c, &f_ref, 1, &again[k - 50]), fmi2OK);
            }
            if (memcmp(first, again, sizeof first) != 0) {
                fprintf(stderr, "the %s state did not repeat the steps bit for bit\n", cycle ? "deserialized" : "restored");
                return 10;
            }
            EXPECT(fmi2DeSerializeFMUstate(c, bytes, size, &restored), fmi2OK);
            EXPECT(fmi2SetFMUstate(c, restored), fmi2OK);
        }
        bytes[0] ^= 0xff;           /* not a state of this FMU */
        EXPECT(fmi2DeSerializeFMUstate(c, bytes, size, &restored), fmi2Error);
        free(bytes);

        /* directional derivatives: finite where they can be computed, an error (never a crash) where not */
        EXPECT(fmi2GetDirectionalDerivative(c, &f_ref, 1, xv, 2, seed, dF), fmi2OK);
        if (!isfinite(dF[0])) return 12;
        EXPECT(fmi2GetDirectionalDerivative(c, &f_ref, 1, xv, 0, seed, dF), fmi2OK);
        EXPECT(fmi2GetDirectionalDerivative(c, &f_ref, 0, xv, 2, seed, dF), fmi2OK);
        EXPECT(fmi2GetDirectionalDerivative(c, &bad_ref, 1, xv, 2, seed, dF), fmi2Error);
        EXPECT(fmi2GetDirectionalDerivative(c, &f_ref, 1, &bad_ref, 1, seed, dF), fmi2Error);
        EXPECT(fmi2GetDirectionalDerivative(c, xv, 1, xv, 2, seed, dF), fmi2Error);     /* x is no unknown */
        EXPECT(fmi2GetDirectionalDerivative(c, &f_ref, 1, xv, 2, NULL, dF), fmi2Error);
        EXPECT(fmi2GetDirectionalDerivative(NULL, &f_ref, 1, xv, 2, seed, dF), fmi2Error);
        EXPECT(fmi2SetReal(c, &x_ref, 1, &nan_value), fmi2OK);
        EXPECT(fmi2GetDirectionalDerivative(c, &f_ref, 1, xv, 2, seed, dF), fmi2Error);
        inputs[0] = 2.0;            /* a jump of 2 m from the committed state */
        EXPECT(fmi2SetReal(c, xv, 2, inputs), fmi2OK);
        if (fmi2GetDirectionalDerivative(c, &f_ref, 1, xv, 2, seed, dF) == fmi2OK && !isfinite(dF[0])) return 13;
        EXPECT(fmi2FreeFMUstate(c, &saved), fmi2OK);
        EXPECT(fmi2FreeFMUstate(c, &restored), fmi2OK);
        fmi2FreeInstance(c);
    }
    dlclose(fmu);
    if (messages == 0) {
        fprintf(stderr, "no log message reached the logger\n");
        return 11;
    }
    printf("all checks passed (%d log messages)\n", messages);
    return 0;
}
