/* The native bushing FMU: the types every part shares.
 *
 * One translation unit per FMU (<modelIdentifier>.c, written by the build) includes, in order,
 * this header, the generated bushing_model.c (the models' kernels translated from their Python
 * source, the FMU's axes, variables and parameter rules), the generated bushing_messages.h (the
 * runtime policy's messages), bushing_instance.h and the instance's parts by concern
 * (instance_log.c, _parameters.c, _life_cycle.c, _variables.c, _cosimulation.c,
 * _model_exchange.c, _derivatives.c, _fmu_state.c; no FMI types) and one of
 * fmi2_functions.c or fmi3_functions.c (the FMI API on top of the instance). Everything but the
 * FMI functions is static: many FMUs of this project load into one process side by side, and
 * an instance keeps all its data in itself (no global state).
 *
 * Units as in the Python models: the kernels work in mm (or rad), mm/s, N (or N.mm) and s;
 * the ports are SI; parameters are in the paper's N-mm-s units (N.mm and rad on rotational
 * axes). */
#ifndef BUSHING_FMU_H
#define BUSHING_FMU_H

#include <stddef.h>

/* The outcome of an instance function; the FMI layer maps it onto fmi2Status / fmi3Status. */
typedef enum { BW_OK = 0, BW_WARNING = 1, BW_DISCARD = 2, BW_ERROR = 3, BW_FATAL = 4 } bw_status;

/* What a variable of the FMU is (fmu_src/fmi/variables.py). */
typedef enum {
    BW_PARAMETER, BW_DISPLACEMENT, BW_VELOCITY, BW_OUTPUT, BW_STATE, BW_DERIVATIVE, BW_INDICATOR, BW_TIME
} bw_kind;

typedef struct {
    const char *name;
    bw_kind kind;
    int axis;          /* position of its axis */
    int index;         /* parameter: position in spec order; state and derivative: kernel state index;
                          indicator: position in the model's switches */
    double scale;      /* port value = scale * kernel value (states, derivatives, indicators) */
} bw_variable;

/* A parameter's allowed range (parameter_specs.ParameterSpec): value >= minimum and <= maximum
 * (> and < if exclusive) where bounded, in words ("> 0", "in (0, 1)") with why; its part in
 * the plausible-force bound: |value| * weight * travel^travel_power * velocity^velocity_power. */
typedef struct {
    const char *name;
    const char *unit;
    int has_minimum;
    double minimum;
    int has_maximum;
    double maximum;
    int exclusive;
    const char *allowed;
    const char *why;
    int in_bound;      /* counts in the plausible bound (BushingModel.bound_powers) */
    int travel_power;
    int velocity_power;
    int weight;        /* the parameter whose |value| weights it (a gain's alpha), or -1 */
} bw_parameter_spec;

/* A condition on several parameters (parameter_specs.Constraint): sum of +-parameter > bound
 * (strict) or >= bound. */
#define BW_MAX_TERMS 4
typedef struct {
    int terms;
    int parameter[BW_MAX_TERMS];
    double coefficient[BW_MAX_TERMS];
    double bound;
    int strict;
    int error;          /* 1: the set is unusable; 0: a warning */
    const char *expression;
    const char *unit;
    const char *why;
} bw_constraint;

/* A model's coupled form on a group of axes (definition.CoupledKernels): its kernels on
 * 3-vectors x, v, a jump and the force (a group of two axes has a zero third component), the state
 * flat (component c of vector i at 3*i + c), the model's constants as its one-axis kernels take
 * them. Tangents in the direction (d_state, dx, dv); jump_tangent takes the state through a jump
 * and writes d(state after the jump) in the jump's direction d_jump. */
typedef struct {
    int states;
    int switches;
    int zero_parameters;          /* how many of the model's parameters a group requires to be 0 */
    int zero_parameter[BW_MAX_TERMS];
    void (*initial_state)(const void *constants, const double *x0, double *state);
    int (*step)(const void *constants, double *state, const double *state_x, const double *x, const double *v,
                double h, int max_substeps);
    int (*jump)(const void *constants, double *state, const double *jump);
    void (*force)(const void *constants, const double *state, const double *x, const double *v, double *force);
    void (*derivatives)(const void *constants, const double *state, const double *x, const double *v,
                        double *rates);
    void (*switch_values)(const void *constants, const double *state, const double *x, const double *v,
                          double *values);
    int (*update)(const void *constants, double *state, const double *x, const double *v);
    void (*force_tangent)(const void *constants, const double *state, const double *x, const double *v,
                          const double *d_state, const double *dx, const double *dv, double *d_force);
    void (*derivatives_tangent)(const void *constants, const double *state, const double *x, const double *v,
                                const double *d_state, const double *dx, const double *dv, double *d_rates);
    int (*jump_tangent)(const void *constants, double *state, const double *jump, const double *d_jump,
                        double *d_state);
} bw_coupled_model;

/* A model: its parameter rules and its kernels (generated wrappers around the translated
 * Python kernels; the constants are the model's own struct, behind void pointers). */
typedef struct {
    const char *name;
    int parameters;     /* the model's own (what prepare takes) */
    int fmu_parameters; /* and its mounting's after them (definition.MOUNTING_SPECS): specs has this many */
    int offset;         /* the mounting's offset and preload among them, or -1 (a model with its own preload) */
    int preload;
    int held;           /* the held force at rest among them (definition.HELD_FORCE_SPEC), or -1 (none) */
    int states;
    int switches;
    const bw_parameter_spec *specs;
    int constraints;
    const bw_constraint *constraint;
    void (*prepare)(const double *parameters, void *constants);
    void (*initial_state)(const void *constants, double x0, double *state);
    int (*step)(const void *constants, double *state, double state_x, double x, double v, double h, int max_substeps);
    int (*jump)(const void *constants, double *state, double jump);
    double (*force)(const void *constants, const double *state, double x, double v);
    void (*derivatives)(const void *constants, const double *state, double x, double v, double *rates);
    void (*switch_values)(const void *constants, const double *state, double x, double v, double *values);
    int (*update)(const void *constants, double *state, double x, double v);   /* 1 if the state changed */
    /* Tangents generated from the kernels (fmu_src/kernels/tangents.py), in the direction (d_state, dx, dv):
       dF, and d(rates); jump_tangent takes the state through a jump, as jump does, and writes
       d(state after the jump)/d(jump). */
    double (*force_tangent)(const void *constants, const double *state, double x, double v, const double *d_state,
                            double dx, double dv);
    void (*derivatives_tangent)(const void *constants, const double *state, double x, double v, const double *d_state,
                                double dx, double dv, double *d_rates);
    int (*jump_tangent)(const void *constants, double *state, double jump, double *d_state);
    /* At rest at x0 holding force (kernel units): BushingModel.resting_state; NULL for a model that holds none. */
    void (*resting_state)(const void *constants, double x0, double force, double *state);
    const bw_coupled_model *coupled;   /* its coupled form, where a coupled group of this FMU runs it; else NULL */
} bw_model;

/* A coupled group of axes (axes.Coupling): its members, positions among the axes, in order. */
typedef struct {
    const char *label;          /* how messages name it: "the radial group (x, y): " */
    int members;
    int axis[3];
} bw_group_spec;

/* An axis of the FMU (fmu_src/fmi/axes.py): its ports, units and model. */
typedef struct {
    const char *name;           /* x, y, z, rx, ry, rz; "" for a one-axis FMU */
    const char *label;          /* how messages name it: "axis rz: ", or "" for a one-axis FMU */
    const char *displacement;   /* port names */
    const char *velocity;
    const char *output;
    int rotational;
    double to_kernel;           /* port displacement -> kernel: m -> mm (1000) or rad -> rad (1) */
    double from_kernel;         /* kernel force -> port: N -> N (1) or N.mm -> N.m (1e-3) */
    double travel_limit;        /* port displacement above which the FMU warns (once) */
    double plausible_travel;    /* kernel units, for the plausible-force bound */
    double plausible_velocity;
    const bw_model *model;
    const double *defaults;     /* the parameters' start values */
} bw_axis_spec;

#endif
