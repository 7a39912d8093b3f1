/* A minimal non-Python FMI 2.0 co-simulation host, for tests/fmu_src/fmi/test_c_host.py and
 * tests/fmu_src/fmi/test_native_fmu.py: it loads an FMU's shared library the way a C/C++ tool does.
 *
 * usage: fmi2_host LIBPYTHON FMU_SO MODEL_GUID RESOURCES_URI REF_X REF_V REF_F STEPS STEP_S
 *
 * pythonfmu's binary does not link libpython: its Python symbols must already be in the
 * process, so the host loads libpython with RTLD_GLOBAL first (a tool would use LD_PRELOAD);
 * LIBPYTHON "-" loads none (a native FMU). It drives x = 2 mm * sin(2*pi*10*t) with the exact
 * velocity, prints "t F" after each step and every log message on stderr, and exits non-zero
 * on any status other than OK. On Linux it ends by saying on stderr whether libpython was
 * mapped into the process ("python in process: yes/no"). It builds for Windows too (mingw-w64),
 * where it loads the FMU's DLL with LoadLibrary. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _WIN32
#include <windows.h>
typedef HMODULE library;
static library open_library(const char *path, int global) { (void)global; return LoadLibraryA(path); }
static void *symbol(library handle, const char *name) { return (void *)(size_t)GetProcAddress(handle, name); }
static const char *library_error(void) { return "LoadLibrary failed"; }
#else
#include <dlfcn.h>
typedef void *library;
static library open_library(const char *path, int global) { return dlopen(path, RTLD_NOW | (global ? RTLD_GLOBAL : RTLD_LOCAL)); }
static void *symbol(library handle, const char *name) { return dlsym(handle, name); }
static const char *library_error(void) { return dlerror(); }
#endif

typedef void *fmi2Component;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Boolean;
typedef const char *fmi2String;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef struct {
    void (*logger)(void *, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(void *, fmi2Status);
    void *componentEnvironment;
} fmi2CallbackFunctions;

static void logger(void *env, fmi2String name, fmi2Status status, fmi2String category, fmi2String message, ...) {
    (void)env;
    fprintf(stderr, "[%s] status %d category %s: %s\n", name, status, category, message);
}

typedef fmi2Component (*Instantiate)(fmi2String, fmi2Type, fmi2String, fmi2String,
                                     const fmi2CallbackFunctions *, fmi2Boolean, fmi2Boolean);
typedef fmi2Status (*SetupExperiment)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, fmi2Real);
typedef fmi2Status (*Transition)(fmi2Component);
typedef fmi2Status (*SetReal)(fmi2Component, const fmi2ValueReference *, size_t, const fmi2Real *);
typedef fmi2Status (*GetReal)(fmi2Component, const fmi2ValueReference *, size_t, fmi2Real *);
typedef fmi2Status (*DoStep)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);
typedef void (*FreeInstance)(fmi2Component);

#define LOAD(type, name) type name = (type)symbol(fmu, #name); if (!name) { fprintf(stderr, "missing %s\n", #name); return 3; }
#define CHECK(call) do { fmi2Status s_ = (call); if (s_ != fmi2OK) { fprintf(stderr, "%s returned %d\n", #call, s_); return 4; } } while (0)

int main(int argc, char **argv) {
    if (argc != 10) { fprintf(stderr, "usage: see source\n"); return 1; }
    if (strcmp(argv[1], "-") != 0 && !open_library(argv[1], 1)) {
        fprintf(stderr, "libpython: %s\n", library_error());
        return 2;
    }
    library fmu = open_library(argv[2], 0);
    if (!fmu) { fprintf(stderr, "fmu: %s\n", library_error()); return 2; }
    LOAD(Instantiate, fmi2Instantiate)
    LOAD(SetupExperiment, fmi2SetupExperiment)
    LOAD(Transition, fmi2EnterInitializationMode)
    LOAD(Transition, fmi2ExitInitializationMode)
    LOAD(SetReal, fmi2SetReal)
    LOAD(GetReal, fmi2GetReal)
    LOAD(DoStep, fmi2DoStep)
    LOAD(Transition, fmi2Terminate)
    LOAD(FreeInstance, fmi2FreeInstance)

    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    fmi2Component c = fmi2Instantiate("c_host", fmi2CoSimulation, argv[3], argv[4], &callbacks, 0, 1);
    if (!c) { fprintf(stderr, "fmi2Instantiate failed\n"); return 4; }
    fmi2ValueReference inputs[2] = {(fmi2ValueReference)atoi(argv[5]), (fmi2ValueReference)atoi(argv[6])};
    fmi2ValueReference output = (fmi2ValueReference)atoi(argv[7]);
    int steps = atoi(argv[8]);
    double h = atof(argv[9]), pi = acos(-1.0);
    CHECK(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0));
    CHECK(fmi2EnterInitializationMode(c));
    CHECK(fmi2ExitInitializationMode(c));
    for (int k = 0; k < steps; ++k) {
        double t = k * h;
        fmi2Real values[2] = {0.002 * sin(2 * pi * 10 * t), 0.002 * 2 * pi * 10 * cos(2 * pi * 10 * t)};
        fmi2Real force;
        CHECK(fmi2SetReal(c, inputs, 2, values));
        CHECK(fmi2DoStep(c, t, h, 1));
        CHECK(fmi2GetReal(c, &output, 1, &force));
        printf("%.17g %.17g\n", t + h, force);
    }
    CHECK(fmi2Terminate(c));
    fmi2FreeInstance(c);
#ifdef __linux__
    {
        FILE *maps = fopen("/proc/self/maps", "r");
        char line[4096];
        int python = 0;
        while (maps && fgets(line, sizeof line, maps)) python = python || strstr(line, "libpython") != NULL;
        if (maps) fclose(maps);
        fprintf(stderr, "python in process: %s\n", python ? "yes" : "no");
    }
#endif
    return 0;
}
