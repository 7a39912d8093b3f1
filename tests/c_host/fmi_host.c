/* A minimal C co-simulation master for FMI 2.0 and 3.0, for tests/fmu_src/fmi/test_platforms.py: it runs a
 * native FMU's library the way a C/C++ tool does, on any CPU it is compiled for (under qemu-user
 * for another one), reading its inputs from stdin so that every binary gets the same bits.
 *
 * usage: fmi_host FMI_VERSION LIBRARY TOKEN RESOURCES INPUT_REFS OUTPUT_REFS STEP_S < inputs
 *
 * FMI_VERSION 2 or 3; TOKEN the guid (FMI 2) or instantiation token (FMI 3); RESOURCES the
 * resource URI (FMI 2) or path (FMI 3), "-" for none; INPUT_REFS and OUTPUT_REFS comma-separated
 * value references. Each line of stdin holds one value per input (a C double literal); for line k
 * the host sets the inputs, steps from k*STEP_S to (k+1)*STEP_S and prints the outputs, "%a"
 * (hexadecimal, exact) separated by spaces. Log messages go to stderr; any status other than OK
 * ends it with a non-zero exit status. */
#include <dlfcn.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_PORTS 64

typedef enum { OK, WARNING, DISCARD, ERROR, FATAL } Status;  /* the same numbers in FMI 2 and 3 */

static void log2_message(void *env, const char *name, int status, const char *category, const char *message, ...) {
    (void)env;
    fprintf(stderr, "[%s] status %d category %s: %s\n", name, status, category, message);
}

static void log3_message(void *env, int status, const char *category, const char *message) {
    (void)env;
    fprintf(stderr, "status %d category %s: %s\n", status, category, message);
}

typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(void *, int);
    void *componentEnvironment;
} Fmi2Callbacks;

typedef void *(*Fmi2Instantiate)(const char *, int, const char *, const char *, const Fmi2Callbacks *, int, int);
typedef int (*Fmi2SetupExperiment)(void *, int, double, double, int, double);
typedef int (*Fmi2Transition)(void *);
typedef int (*Fmi2Reals)(void *, const unsigned int *, size_t, double *);
typedef int (*Fmi2DoStep)(void *, double, double, int);
typedef void (*FreeInstance)(void *);

/* fmi3Boolean is C's bool, fmi2Boolean an int */
typedef void *(*Fmi3Instantiate)(const char *, const char *, const char *, bool, bool, bool, bool,
                                 const unsigned int *, size_t, void *, void (*)(void *, int, const char *, const char *),
                                 void *);
typedef int (*Fmi3EnterInitialization)(void *, bool, double, double, bool, double);
typedef int (*Fmi3Transition)(void *);
typedef int (*Fmi3Floats)(void *, const unsigned int *, size_t, double *, size_t);
typedef int (*Fmi3DoStep)(void *, double, double, bool, bool *, bool *, bool *, double *);

static void *library;

static void *load(const char *name) {
    void *function = dlsym(library, name);
    if (!function) {
        fprintf(stderr, "missing %s\n", name);
        exit(3);
    }
    return function;
}

static void check(int status, const char *call) {
    if (status != OK) {
        fprintf(stderr, "%s returned %d\n", call, status);
        exit(4);
    }
}

static size_t references(const char *text, unsigned int *refs) {
    size_t count = 0;
    char *end;
    while (*text && count < MAX_PORTS) {
        refs[count++] = (unsigned int)strtoul(text, &end, 10);
        text = *end == ',' ? end + 1 : end;
    }
    return count;
}

static int read_inputs(double *values, size_t count) {
    for (size_t i = 0; i < count; ++i)
        if (scanf("%lf", &values[i]) != 1) return 0;
    return 1;
}

static void print_outputs(const double *values, size_t count) {
    for (size_t i = 0; i < count; ++i) printf(i ? " %a" : "%a", values[i]);
    printf("\n");
}

static void run_fmi2(const char *token, const char *resources, const unsigned int *in, size_t n_in,
                     const unsigned int *out, size_t n_out, double h) {
    Fmi2Callbacks callbacks = {log2_message, calloc, free, NULL, NULL};
    void *c = ((Fmi2Instantiate)load("fmi2Instantiate"))("fmi_host", 1, token, resources, &callbacks, 0, 1);
    Fmi2Reals set = (Fmi2Reals)load("fmi2SetReal"), get = (Fmi2Reals)load("fmi2GetReal");
    Fmi2DoStep step = (Fmi2DoStep)load("fmi2DoStep");
    double inputs[MAX_PORTS], outputs[MAX_PORTS];
    if (!c) { fprintf(stderr, "fmi2Instantiate failed\n"); exit(4); }
    check(((Fmi2SetupExperiment)load("fmi2SetupExperiment"))(c, 0, 0.0, 0.0, 0, 0.0), "fmi2SetupExperiment");
    check(((Fmi2Transition)load("fmi2EnterInitializationMode"))(c), "fmi2EnterInitializationMode");
    check(((Fmi2Transition)load("fmi2ExitInitializationMode"))(c), "fmi2ExitInitializationMode");
    for (long k = 0; read_inputs(inputs, n_in); ++k) {
        check(set(c, in, n_in, inputs), "fmi2SetReal");
        check(step(c, (double)k * h, h, 1), "fmi2DoStep");
        check(get(c, out, n_out, outputs), "fmi2GetReal");
        print_outputs(outputs, n_out);
    }
    check(((Fmi2Transition)load("fmi2Terminate"))(c), "fmi2Terminate");
    ((FreeInstance)load("fmi2FreeInstance"))(c);
}

static void run_fmi3(const char *token, const char *resources, const unsigned int *in, size_t n_in,
                     const unsigned int *out, size_t n_out, double h) {
    void *c = ((Fmi3Instantiate)load("fmi3InstantiateCoSimulation"))(
        "fmi_host", token, resources, false, true, false, false, NULL, 0, NULL, log3_message, NULL);
    Fmi3Floats set = (Fmi3Floats)load("fmi3SetFloat64"), get = (Fmi3Floats)load("fmi3GetFloat64");
    Fmi3DoStep step = (Fmi3DoStep)load("fmi3DoStep");
    double inputs[MAX_PORTS], outputs[MAX_PORTS], last_time;
    bool event, terminate, early;
    if (!c) { fprintf(stderr, "fmi3InstantiateCoSimulation failed\n"); exit(4); }
    check(((Fmi3EnterInitialization)load("fmi3EnterInitializationMode"))(c, false, 0.0, 0.0, false, 0.0),
          "fmi3EnterInitializationMode");
    check(((Fmi3Transition)load("fmi3ExitInitializationMode"))(c), "fmi3ExitInitializationMode");
    for (long k = 0; read_inputs(inputs, n_in); ++k) {
        check(set(c, in, n_in, inputs, n_in), "fmi3SetFloat64");
        check(step(c, (double)k * h, h, true, &event, &terminate, &early, &last_time), "fmi3DoStep");
        check(get(c, out, n_out, outputs, n_out), "fmi3GetFloat64");
        print_outputs(outputs, n_out);
    }
    check(((Fmi3Transition)load("fmi3Terminate"))(c), "fmi3Terminate");
    ((FreeInstance)load("fmi3FreeInstance"))(c);
}

int main(int argc, char **argv) {
    unsigned int in[MAX_PORTS], out[MAX_PORTS];
    if (argc != 8) { fprintf(stderr, "usage: see source\n"); return 1; }
    library = dlopen(argv[2], RTLD_NOW | RTLD_LOCAL);
    if (!library) { fprintf(stderr, "library: %s\n", dlerror()); return 2; }
    const char *resources = strcmp(argv[4], "-") == 0 ? NULL : argv[4];
    size_t n_in = references(argv[5], in), n_out = references(argv[6], out);
    double h = strtod(argv[7], NULL);
    if (strcmp(argv[1], "3") == 0) run_fmi3(argv[3], resources, in, n_in, out, n_out, h);
    else run_fmi2(argv[3], resources, in, n_in, out, n_out, h);
    return 0;
}
