/* The instance of a native bushing FMU: what fmu_src/fmi/pythonfmu_slave.py does for the pythonfmu
 * FMU, with the same variables, conventions and messages, and the error statuses pythonfmu
 * cannot give (an invalid start value is an error at the exit of initialization mode).
 *
 * Compiled after the generated bushing_model.c, which defines BW_AXES, BW_VARIABLES,
 * BW_MAX_PARAMETERS, BW_MAX_STATES, BW_MAX_SWITCHES, bw_constants (a union of the models'
 * constant structs), bw_axis_specs[], bw_variables[] and BW_KERNEL_OK / BW_KERNEL_TOO_MANY_SUBSTEPS
 * / BW_KERNEL_NOT_FINITE / BW_MAX_SUBSTEPS (the Python kernels' status codes and substep limit).
 *
 * Conventions (README "Conventions"): over a communication step [t, t + h) the displacement is
 * x + v*(t' - t); a step that starts away from the displacement the state belongs to takes the
 * difference as a displacement jump; the output has direct feedthrough of x and v; at the exit
 * of initialization mode every axis is in relaxed equilibrium at its x. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define BW_MESSAGE 1024

/* How the FMI layer hears of a message: status, category, text (already formatted). */
typedef void (*bw_log_function)(void *fmi_instance, bw_status status, const char *category, const char *message);

typedef struct {
    double parameters[BW_MAX_PARAMETERS];   /* the model's, then its mounting's (offset, preload) */
    double x, v;                     /* the ports as set (m or rad, per s) */
    double x_now;                    /* the model's displacement: x as set less the offset, else x_k + v_k*h */
    double state[BW_MAX_STATES];     /* committed, kernel units */
    double state_x;                  /* kernel displacement the committed state belongs to */
    double last_output;              /* last finite output, port units */
    int output_is_current;
    int parameters_changed;
    int usable;                      /* the parameters in force passed validation */
    double output_bound;             /* port units; above it the output is implausible */
    int travel_warned, output_warned, stale_output_logged;
    bw_constants constants;
} bw_axis;

/* A coupled group of axes (bw_group_specs): one state of its model's coupled form on its members'
   displacement vector; each member keeps its ports, parameters, mounting and output. */
typedef struct {
    double state[BW_MAX_GROUP_STATES];   /* committed, kernel units */
    double state_x[3];                   /* kernel displacement vector the committed state belongs to */
    int usable;                          /* its members' parameters are one usable set */
    int equal;                           /* its members' parameters are equal (checked at each change) */
    int parameters_changed;
} bw_group;

/* Everything an FMU state saves and restores: the instance's data without its callbacks. */
typedef struct {
    bw_axis axes[BW_AXES];
    bw_group groups[BW_GROUP_SLOTS];
    int initial_state_pending;       /* set at the exit of initialization, or at the first valid step */
    double time;
} bw_data;

#define BW_CATEGORIES 5
static const char *const bw_categories[BW_CATEGORIES] = {
    "logStatusWarning", "logStatusDiscard", "logStatusError", "logStatusFatal", "logAll"};

typedef struct {
    bw_data data;
    int model_exchange;              /* 1: a model-exchange instance (the host integrates the states) */
    int logging_on;
    int category_enabled[BW_CATEGORIES];
    int initialized;                 /* the exit of initialization mode succeeded */
    bw_log_function log;
    void *fmi_instance;              /* passed back to log */
    unsigned long long jump_history[BW_AXES];   /* bit i: the step i steps ago started with a jump */
    int jump_warned;                 /* the jumping-inputs warning is given once per instance */
} bw_instance;
