/* Time a native FMU's co-simulation step in a plain C master (no Python anywhere), for
 * benchmarks/bench_fmu_step.py: set every axis's displacement and velocity, doStep(1 ms), get
 * every output, STEPS times; REPEATS runs, each in a fresh instance; prints the nanoseconds per
 * step of every run, one per line.
 *
 * usage: c_master_timing FMU_SO GUID STEPS REPEATS AXES VR_X VR_V VR_F [VR_X VR_V VR_F ...]
 * The first three axes are driven by 2 mm / 10 Hz sines (in m), the others by 0.02 rad / 10 Hz; in
 * phase, or with C_MASTER_PHASED set in the environment a third of a half period apart axis by axis
 * (axis a at the phase a*pi/3: a coupled group then moves in its plane, not along a line). */
#define _POSIX_C_SOURCE 199309L   /* clock_gettime under -std=c99 */
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "fmi2Functions.h"

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
    (void)env;
    (void)name;
    (void)status;
    (void)category;
    fprintf(stderr, "%s\n", message);
}

#define LOAD(name)                                                                                                 \
    name##TYPE *name = (name##TYPE *)dlsym(fmu, #name);                                                            \
    if (!name) return 3

int main(int argc, char **argv) {
    void *fmu;
    int steps, repeats, axes, a, k, r;
    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    fmi2ValueReference inputs[12], outputs[6];
    double values[12], forces[6], *amplitudes, *rates, pi = acos(-1.0), h = 1e-3, sink = 0.0;
    double cos_phase[6], sin_phase[6];
    int phased = getenv("C_MASTER_PHASED") != NULL;
    if (argc < 9) return 1;
    fmu = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!fmu) {
        fprintf(stderr, "%s\n", dlerror());
        return 2;
    }
    steps = atoi(argv[3]);
    repeats = atoi(argv[4]);
    axes = atoi(argv[5]);
    if (axes < 1 || axes > 6 || argc != 6 + 3 * axes) return 1;
    for (a = 0; a < axes; a++) {
        cos_phase[a] = cos(a * pi / 3.0);
        sin_phase[a] = sin(a * pi / 3.0);
        inputs[2 * a] = (fmi2ValueReference)atoi(argv[6 + 3 * a]);
        inputs[2 * a + 1] = (fmi2ValueReference)atoi(argv[7 + 3 * a]);
        outputs[a] = (fmi2ValueReference)atoi(argv[8 + 3 * a]);
    }
    /* the inputs of every step, computed before the clock starts */
    amplitudes = (double *)malloc(sizeof(double) * (size_t)steps * 2);
    rates = amplitudes + steps;
    if (!amplitudes) return 4;
    for (k = 0; k < steps; k++) {
        amplitudes[k] = sin(2 * pi * 10 * k * h);
        rates[k] = 2 * pi * 10 * cos(2 * pi * 10 * k * h);
    }
    {
        LOAD(fmi2Instantiate);
        LOAD(fmi2SetupExperiment);
        LOAD(fmi2EnterInitializationMode);
        LOAD(fmi2ExitInitializationMode);
        LOAD(fmi2SetReal);
        LOAD(fmi2GetReal);
        LOAD(fmi2DoStep);
        LOAD(fmi2FreeInstance);
        for (r = 0; r < repeats; r++) {
            struct timespec start, end;
            fmi2Component c = fmi2Instantiate("timing", fmi2CoSimulation, argv[2], "", &callbacks, 0, 0);
            if (!c) return 5;
            if (fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) || fmi2EnterInitializationMode(c) ||
                fmi2ExitInitializationMode(c))
                return 6;
            clock_gettime(CLOCK_MONOTONIC, &start);
            for (k = 0; k < steps; k++) {
                for (a = 0; a < axes; a++) {
                    double scale = a < 3 ? 2e-3 : 0.02;
                    if (phased) {   /* sin(wt + phase) and its rate, by the angle-addition identities */
                        values[2 * a] = scale * (amplitudes[k] * cos_phase[a] + rates[k] / (2 * pi * 10) * sin_phase[a]);
                        values[2 * a + 1] = scale * (rates[k] * cos_phase[a] - 2 * pi * 10 * amplitudes[k] * sin_phase[a]);
                    } else {
                        values[2 * a] = scale * amplitudes[k];
                        values[2 * a + 1] = scale * rates[k];
                    }
                }
                if (fmi2SetReal(c, inputs, 2 * (size_t)axes, values) != fmi2OK) return 7;
                if (fmi2DoStep(c, k * h, h, fmi2True) != fmi2OK) return 8;
                if (fmi2GetReal(c, outputs, (size_t)axes, forces) != fmi2OK) return 9;
                sink += forces[0];
            }
            clock_gettime(CLOCK_MONOTONIC, &end);
            printf("%.3f\n", ((end.tv_sec - start.tv_sec) * 1e9 + (end.tv_nsec - start.tv_nsec)) / steps);
            fmi2FreeInstance(c);
        }
    }
    free(amplitudes);
    return sink == 12345.678 ? 10 : 0;   /* keeps the forces used */
}
