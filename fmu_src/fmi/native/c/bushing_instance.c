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

/* ------------------------------------------------------------------------------- messages */

/* A double as Python's repr writes it: the fewest significant digits that read back as the
   same double, in fixed notation for exponents -4 to 15 (with ".0" for a whole number) and
   in scientific notation otherwise; so the messages name values as the Python FMU and the
   parameter files do. */
static void bw_format_double(char *out, size_t size, double value) {
    char scientific[40];
    int digits, exponent;
    if (isnan(value)) { snprintf(out, size, "nan"); return; }
    if (isinf(value)) { snprintf(out, size, value > 0 ? "inf" : "-inf"); return; }
    for (digits = 1; digits < 17; digits++) {
        snprintf(scientific, sizeof scientific, "%.*e", digits - 1, value);
        if (strtod(scientific, NULL) == value) break;
    }
    snprintf(scientific, sizeof scientific, "%.*e", digits - 1, value);
    exponent = atoi(strchr(scientific, 'e') + 1);
    if (exponent < -4 || exponent >= 16) {
        snprintf(out, size, "%s", scientific);
        return;
    }
    snprintf(out, size, "%.*f", digits - 1 - exponent > 0 ? digits - 1 - exponent : 0, value);
    if (!strchr(out, '.') && strlen(out) + 2 < size) strcat(out, ".0");
}

/* Whether a message goes to the host: warnings and errors always (a host that does not switch
   logging on still learns why a call failed, as with the Reference-FMUs); other messages only
   with logging on and their category enabled. */
static int bw_log_wanted(const bw_instance *inst, bw_status status, const char *category) {
    int k;
    if (!inst->log) return 0;
    if (status != BW_OK) return 1;
    if (!inst->logging_on) return 0;
    for (k = 0; k < BW_CATEGORIES; k++) {
        if (strcmp(category, bw_categories[k]) == 0) return inst->category_enabled[k];
    }
    return 1;
}

static void bw_log(bw_instance *inst, bw_status status, const char *category, const char *format, ...) {
    char message[BW_MESSAGE];
    va_list arguments;
    if (!bw_log_wanted(inst, status, category)) return;
    va_start(arguments, format);
    vsnprintf(message, sizeof message, format, arguments);
    va_end(arguments);
    inst->log(inst->fmi_instance, status, category, message);
}

static void bw_error(bw_instance *inst, const char *format, const char *text) {
    bw_log(inst, BW_ERROR, "logStatusError", format, text);
}

/* ------------------------------------------------------------------------------- parameters */

/* The mounting (definition.MOUNTING_SPECS): F = model(x - offset) + preload, kernel units. */
static double bw_offset(const bw_axis *axis, const bw_model *model) {
    return model->offset >= 0 ? axis->parameters[model->offset] : 0.0;
}

static double bw_preload(const bw_axis *axis, const bw_model *model) {
    return model->preload >= 0 ? axis->parameters[model->preload] : 0.0;
}

/* ------------------------------------------------------------------------------- coupled groups */

static const bw_coupled_model *bw_group_kernels(int g) {
    return bw_axis_specs[bw_group_specs[g].axis[0]].model->coupled;
}

static const void *bw_group_constants(const bw_instance *inst, int g) {
    return &inst->data.axes[bw_group_specs[g].axis[0]].constants;
}

/* The members' model displacements and velocities as 3-vectors (kernel units; 0 beyond them). */
static void bw_group_inputs(const bw_instance *inst, int g, double *x, double *v) {
    const bw_group_spec *spec = &bw_group_specs[g];
    int c;
    for (c = 0; c < 3; c++) x[c] = v[c] = 0.0;
    for (c = 0; c < spec->members; c++) {
        const bw_axis *axis = &inst->data.axes[spec->axis[c]];
        x[c] = axis->x_now;
        v[c] = axis->v * bw_axis_specs[spec->axis[c]].to_kernel;
    }
}

/* Whether the members' own parameters are one set (their mounting may differ), and the coupled
   model's zero parameters 0 (Spencer's x0); logs every difference, naming the group, the axes and
   the values (as parameter_files.check_groups). */
static int bw_check_group(bw_instance *inst, int g) {
    const bw_group_spec *spec = &bw_group_specs[g];
    const bw_model *model = bw_axis_specs[spec->axis[0]].model;
    const bw_axis *first = &inst->data.axes[spec->axis[0]];
    char a[40], b[40], values[256];
    int i, c, equal = 1;
    for (i = 0; i < model->parameters; i++) {
        for (c = 1; c < spec->members; c++) {
            const bw_axis *other = &inst->data.axes[spec->axis[c]];
            if (other->parameters[i] == first->parameters[i]) continue;
            bw_format_double(a, sizeof a, first->parameters[i]);
            bw_format_double(b, sizeof b, other->parameters[i]);
            snprintf(values, sizeof values, "%s.%s = %s, %s.%s = %s [%s]", bw_axis_specs[spec->axis[0]].name,
                     model->specs[i].name, a, bw_axis_specs[spec->axis[c]].name, model->specs[i].name, b,
                     model->specs[i].unit);
            BW_MESSAGE_GROUP_PARAMETERS_DIFFER(inst, spec->label, values);
            equal = 0;
        }
    }
    for (i = 0; i < model->coupled->zero_parameters; i++) {
        int k = model->coupled->zero_parameter[i];
        if (first->parameters[k] == 0.0) continue;
        bw_format_double(a, sizeof a, first->parameters[k]);
        BW_MESSAGE_GROUP_PARAMETER_NOT_ZERO(inst, spec->label, model->specs[k].name, a, model->specs[k].unit);
        equal = 0;
    }
    return equal;
}

/* Validate and prepare one axis's parameters (as BushingModel.validate), logging every
   problem; 1 if usable. Warnings are logged once per change, as the Python FMU does. */
static int bw_check_axis(bw_instance *inst, int a) {
    bw_axis *axis = &inst->data.axes[a];
    const bw_axis_spec *spec = &bw_axis_specs[a];
    const bw_model *model = spec->model;
    char value[40];
    int i, t, errors = 0;
    for (i = 0; i < model->fmu_parameters; i++) {
        const bw_parameter_spec *p = &model->specs[i];
        double x = axis->parameters[i];
        if (!isfinite(x)) {
            bw_format_double(value, sizeof value, x);
            BW_MESSAGE_PARAMETER_NOT_FINITE(inst, spec->label, p->name, value, p->unit);
            errors++;
        }
    }
    if (!errors) {
        for (i = 0; i < model->fmu_parameters; i++) {
            const bw_parameter_spec *p = &model->specs[i];
            double x = axis->parameters[i];
            int above = !p->has_minimum || (p->exclusive ? x > p->minimum : x >= p->minimum);
            int below = !p->has_maximum || (p->exclusive ? x < p->maximum : x <= p->maximum);
            if (!(above && below)) {
                char why[160] = "";
                if (p->why[0]) snprintf(why, sizeof why, " (%s)", p->why);
                bw_format_double(value, sizeof value, x);
                BW_MESSAGE_PARAMETER_OUT_OF_RANGE(inst, spec->label, p->name, value, p->unit, p->allowed, why);
                errors++;
            }
        }
        for (i = 0; i < model->constraints; i++) {
            const bw_constraint *c = &model->constraint[i];
            double sum = 0.0;
            char bound[40], unit[40];
            for (t = 0; t < c->terms; t++) sum += c->coefficient[t] * axis->parameters[c->parameter[t]];
            if (c->strict ? sum > c->bound : sum >= c->bound) continue;
            bw_format_double(value, sizeof value, sum);
            snprintf(bound, sizeof bound, "%s %g", c->strict ? ">" : ">=", c->bound);
            snprintf(unit, sizeof unit, "%s%s", c->unit[0] ? " " : "", c->unit);
            if (c->error) {
                BW_MESSAGE_CONSTRAINT_BROKEN(inst, spec->label, c->expression, value, unit, bound, c->why);
                errors++;
            }
        }
    }
    axis->usable = !errors;
    if (errors) return 0;
    for (i = 0; i < model->constraints; i++) {
        const bw_constraint *c = &model->constraint[i];
        double sum = 0.0;
        char bound[40], unit[40];
        for (t = 0; t < c->terms; t++) sum += c->coefficient[t] * axis->parameters[c->parameter[t]];
        if (c->error || (c->strict ? sum > c->bound : sum >= c->bound)) continue;
        bw_format_double(value, sizeof value, sum);
        snprintf(bound, sizeof bound, "%s %g", c->strict ? ">" : ">=", c->bound);
        snprintf(unit, sizeof unit, "%s%s", c->unit[0] ? " " : "", c->unit);
        BW_MESSAGE_CONSTRAINT_DOUBTFUL(inst, spec->label, c->expression, value, unit, c->why, bound);
    }
    model->prepare(axis->parameters, &axis->constants);
    {   /* the plausible bound (BushingModel.plausible_force_bound), in port units */
        double total = 0.0, offset, rest[BW_MAX_STATES];
        for (i = 0; i < model->fmu_parameters; i++) {
            const bw_parameter_spec *p = &model->specs[i];
            double weight = p->weight >= 0 ? fabs(axis->parameters[p->weight]) : 1.0;
            if (p->in_bound) {
                total += fabs(axis->parameters[i]) * weight * pow(spec->plausible_travel, p->travel_power)
                         * pow(spec->plausible_velocity, p->velocity_power);
            }
        }
        model->initial_state(&axis->constants, 0.0, rest);
        offset = model->force(&axis->constants, rest, 0.0, 0.0);
        axis->output_bound = (total + fabs(offset)) * spec->from_kernel;
    }
    return 1;
}

/* Check every axis whose parameters changed; 1 if all are usable. */
static int bw_check_parameters(bw_instance *inst) {
    int a, usable = 1;
    for (a = 0; a < BW_AXES; a++) {
        bw_axis *axis = &inst->data.axes[a];
        if (axis->parameters_changed) {
            axis->parameters_changed = 0;
            bw_check_axis(inst, a);
        }
        usable = usable && axis->usable;
    }
    for (a = 0; a < BW_GROUPS; a++) {
        bw_group *group = &inst->data.groups[a];
        const bw_group_spec *spec = &bw_group_specs[a];
        int c, members = 1;
        for (c = 0; c < spec->members; c++) members = members && inst->data.axes[spec->axis[c]].usable;
        if (group->parameters_changed && members) {
            group->parameters_changed = 0;
            group->equal = bw_check_group(inst, a);
        }
        group->usable = members && group->equal && !group->parameters_changed;
        usable = usable && group->usable;
    }
    return usable;
}

/* fmi2/fmi3SetDebugLogging: logging on or off, for every category (none named) or the named ones. */
static bw_status bw_set_debug_logging(bw_instance *inst, int on, size_t count, const char *const categories[]) {
    size_t i;
    int k;
    inst->logging_on = on ? 1 : 0;
    for (k = 0; k < BW_CATEGORIES; k++) inst->category_enabled[k] = count == 0 ? inst->logging_on : 0;
    for (i = 0; i < count; i++) {
        int known = 0;
        for (k = 0; k < BW_CATEGORIES; k++) {
            if (categories[i] && strcmp(categories[i], bw_categories[k]) == 0) {
                inst->category_enabled[k] = inst->logging_on;
                known = 1;
            }
        }
        if (!known) {
            bw_log(inst, BW_ERROR, "logStatusError", "unknown log category %s (this FMU's: logStatusWarning, "
                   "logStatusDiscard, logStatusError, logStatusFatal, logAll)", categories[i] ? categories[i] : "(null)");
            return BW_ERROR;
        }
    }
    return BW_OK;
}

/* ------------------------------------------------------------------------------- life cycle */

static void bw_reset(bw_instance *inst);

/* A new instance's settings (the FMI layer allocated it, zeroed), then its start values. */
static void bw_initialize(bw_instance *inst, int model_exchange, int logging_on, bw_log_function log,
                          void *fmi_instance) {
    inst->model_exchange = model_exchange;
    inst->log = log;
    inst->fmi_instance = fmi_instance;
    bw_set_debug_logging(inst, logging_on, 0, NULL);
    bw_reset(inst);
}

static void bw_reset(bw_instance *inst) {
    int a, i;
    memset(&inst->data, 0, sizeof inst->data);
    for (a = 0; a < BW_AXES; a++) {
        bw_axis *axis = &inst->data.axes[a];
        for (i = 0; i < bw_axis_specs[a].model->fmu_parameters; i++) {
            axis->parameters[i] = bw_axis_specs[a].defaults[i];
        }
        axis->x_now = -bw_offset(axis, bw_axis_specs[a].model);
        axis->parameters_changed = 1;
        if (bw_axis_group[a] >= 0) inst->data.groups[bw_axis_group[a]].parameters_changed = 1;
        axis->output_bound = HUGE_VAL;
    }
    inst->data.initial_state_pending = 1;
    inst->initialized = 0;
    memset(inst->jump_history, 0, sizeof inst->jump_history);
    inst->jump_warned = 0;
}

static void bw_set_initial_state(bw_instance *inst) {
    int a, g;
    for (a = 0; a < BW_AXES; a++) {
        bw_axis *axis = &inst->data.axes[a];
        if (bw_axis_group[a] < 0) bw_axis_specs[a].model->initial_state(&axis->constants, axis->x_now, axis->state);
        axis->state_x = axis->x_now;
        axis->output_is_current = 0;
    }
    for (g = 0; g < BW_GROUPS; g++) {
        bw_group *group = &inst->data.groups[g];
        double v[3];
        bw_group_inputs(inst, g, group->state_x, v);
        bw_group_kernels(g)->initial_state(bw_group_constants(inst, g), group->state_x, group->state);
    }
    inst->data.initial_state_pending = 0;
}

/* The exit of initialization mode: start values that cannot run are an error, each named. */
static bw_status bw_exit_initialization(bw_instance *inst) {
    int a, usable = bw_check_parameters(inst);
    for (a = 0; a < BW_AXES; a++) {
        const bw_axis_spec *spec = &bw_axis_specs[a];
        bw_axis *axis = &inst->data.axes[a];
        if (!isfinite(axis->x) || !isfinite(axis->v)) {
            char value[40];
            int x_bad = !isfinite(axis->x);
            bw_format_double(value, sizeof value, x_bad ? axis->x : axis->v);
            BW_MESSAGE_INPUT_SET_NOT_FINITE(inst, x_bad ? spec->displacement : spec->velocity, value,
                                            x_bad ? (spec->rotational ? "rad" : "m") : (spec->rotational ? "rad/s" : "m/s"));
            usable = 0;
        }
    }
    if (!usable) {
        BW_MESSAGE_CANNOT_START(inst, BW_TEXT_FIX_AND_INSTANTIATE);
        return BW_ERROR;
    }
    bw_set_initial_state(inst);
    inst->initialized = 1;
    return BW_OK;
}

/* ------------------------------------------------------------------------------- variables */

static bw_status bw_set_parameter(bw_instance *inst, const bw_variable *var, double value) {
    bw_axis *axis = &inst->data.axes[var->axis];
    const bw_axis_spec *spec = &bw_axis_specs[var->axis];
    axis->parameters[var->index] = value;
    axis->parameters_changed = 1;
    axis->output_is_current = 0;
    if (bw_axis_group[var->axis] >= 0) {
        const bw_group_spec *group = &bw_group_specs[bw_axis_group[var->axis]];
        int c;
        inst->data.groups[bw_axis_group[var->axis]].parameters_changed = 1;
        for (c = 0; c < group->members; c++) inst->data.axes[group->axis[c]].output_is_current = 0;
    }
    /* the model's displacement moves with the offset (a jump if it changes during the run) */
    if (var->index == spec->model->offset) axis->x_now = axis->x * spec->to_kernel - value;
    if (!isfinite(value)) {
        char text[40];
        bw_format_double(text, sizeof text, value);
        BW_MESSAGE_PARAMETER_SET_NOT_FINITE(inst, spec->label, spec->model->specs[var->index].name, text,
                                            spec->model->specs[var->index].unit);
    }
    return BW_OK;
}

/* An input of axis a changed: its output is stale, and so is every other member's of its group. */
static void bw_inputs_changed(bw_instance *inst, int a) {
    inst->data.axes[a].output_is_current = 0;
    if (bw_axis_group[a] >= 0) {
        const bw_group_spec *group = &bw_group_specs[bw_axis_group[a]];
        int c;
        for (c = 0; c < group->members; c++) inst->data.axes[group->axis[c]].output_is_current = 0;
    }
}

static bw_status bw_set_displacement(bw_instance *inst, int a, double value) {
    bw_axis *axis = &inst->data.axes[a];
    const bw_axis_spec *spec = &bw_axis_specs[a];
    char text[40];
    axis->x = value;
    axis->x_now = value * spec->to_kernel - bw_offset(axis, spec->model);
    bw_inputs_changed(inst, a);
    if (!isfinite(value)) {
        bw_format_double(text, sizeof text, value);
        BW_MESSAGE_INPUT_SET_NOT_FINITE(inst, spec->displacement, text, spec->rotational ? "rad" : "m");
    } else if (fabs(value) > spec->travel_limit && !axis->travel_warned) {
        axis->travel_warned = 1;
        bw_format_double(text, sizeof text, value);
        if (spec->rotational) {
            BW_MESSAGE_ROTATION_BEYOND_SMALL_ANGLES(inst, spec->displacement, text, spec->travel_limit);
        } else {
            BW_MESSAGE_DISPLACEMENT_BEYOND_TRAVEL(inst, spec->displacement, text, spec->travel_limit);
        }
    }
    return BW_OK;
}

static bw_status bw_set_velocity(bw_instance *inst, int a, double value) {
    bw_axis *axis = &inst->data.axes[a];
    const bw_axis_spec *spec = &bw_axis_specs[a];
    axis->v = value;
    bw_inputs_changed(inst, a);
    if (!isfinite(value)) {
        char text[40];
        bw_format_double(text, sizeof text, value);
        BW_MESSAGE_INPUT_SET_NOT_FINITE(inst, spec->velocity, text, spec->rotational ? "rad/s" : "m/s");
    }
    return BW_OK;
}

/* The axis's output at the current inputs: where x was set away from the displacement of the
   committed state (co-simulation), it includes the model's response to that jump. Never NaN:
   where it cannot be computed it keeps its last finite value, and says so once. */
/* A coupled group's outputs at the current inputs (each member's, port units, mounting included),
   the committed state taken through the displacement jump to them in co-simulation; 1 if every one
   is finite. */
static int bw_group_outputs(bw_instance *inst, int g, double *outputs) {
    const bw_group_spec *spec = &bw_group_specs[g];
    const bw_group *group = &inst->data.groups[g];
    const bw_coupled_model *kernels = bw_group_kernels(g);
    const void *constants = bw_group_constants(inst, g);
    double state[BW_MAX_GROUP_STATES], x[3], v[3], force[3];
    int c, status = BW_KERNEL_OK;
    bw_group_inputs(inst, g, x, v);
    memcpy(state, group->state, sizeof state);
    if (!inst->model_exchange && (x[0] != group->state_x[0] || x[1] != group->state_x[1] ||
                                  x[2] != group->state_x[2])) {
        double jump[3];
        for (c = 0; c < 3; c++) jump[c] = x[c] - group->state_x[c];
        status = kernels->jump(constants, state, jump);
    }
    kernels->force(constants, state, x, v, force);
    for (c = 0; c < spec->members; c++) {
        const bw_axis_spec *member = &bw_axis_specs[spec->axis[c]];
        outputs[c] = force[c] * member->from_kernel
                     + bw_preload(&inst->data.axes[spec->axis[c]], member->model) * member->from_kernel;
        if (!isfinite(outputs[c])) status = BW_KERNEL_NOT_FINITE;
    }
    return status == BW_KERNEL_OK;
}

static double bw_output(bw_instance *inst, int a) {
    bw_axis *axis = &inst->data.axes[a];
    const bw_axis_spec *spec = &bw_axis_specs[a];
    const char *reason = BW_TEXT_PARAMETERS_INVALID;
    int g = bw_axis_group[a];
    if (axis->output_is_current) return axis->last_output;
    if (g >= 0) {
        if (bw_check_parameters(inst) || inst->data.groups[g].usable) {
            double outputs[3];
            int c;
            if (bw_group_outputs(inst, g, outputs)) {
                for (c = 0; c < bw_group_specs[g].members; c++) {
                    bw_axis *member = &inst->data.axes[bw_group_specs[g].axis[c]];
                    member->last_output = outputs[c];
                    member->output_is_current = 1;
                    member->stale_output_logged = 0;
                }
                return axis->last_output;
            }
            reason = BW_TEXT_NOT_FINITE_AT_INPUTS;
        }
    } else if (bw_check_parameters(inst) || axis->usable) {
        double state[BW_MAX_STATES], output;
        int status = BW_KERNEL_OK;
        memcpy(state, axis->state, sizeof state);
        if (!inst->model_exchange && axis->x_now != axis->state_x) {
            status = spec->model->jump(&axis->constants, state, axis->x_now - axis->state_x);
        }
        output = spec->model->force(&axis->constants, state, axis->x_now, axis->v * spec->to_kernel)
                 * spec->from_kernel + bw_preload(axis, spec->model) * spec->from_kernel;
        if (status == BW_KERNEL_OK && isfinite(output)) {
            axis->last_output = output;
            axis->output_is_current = 1;
            axis->stale_output_logged = 0;
            return output;
        }
        reason = BW_TEXT_NOT_FINITE_AT_INPUTS;
    }
    if (!axis->stale_output_logged) {
        char text[40];
        axis->stale_output_logged = 1;
        bw_format_double(text, sizeof text, axis->last_output);
        BW_MESSAGE_OUTPUT_NOT_COMPUTABLE(inst, spec->output, reason, text, spec->rotational ? "N.m" : "N");
    }
    return axis->last_output;
}

static bw_status bw_set_real(bw_instance *inst, unsigned int reference, double value) {
    const bw_variable *var;
    if (reference >= BW_VARIABLES) {
        bw_log(inst, BW_ERROR, "logStatusError", "value reference %u does not exist (this FMU has 0 to %d)",
               reference, BW_VARIABLES - 1);
        return BW_ERROR;
    }
    var = &bw_variables[reference];
    switch (var->kind) {
    case BW_PARAMETER: return bw_set_parameter(inst, var, value);
    case BW_DISPLACEMENT: return bw_set_displacement(inst, var->axis, value);
    case BW_VELOCITY: return bw_set_velocity(inst, var->axis, value);
    default:
        bw_log(inst, BW_ERROR, "logStatusError", "%s (value reference %u) is not an input or a parameter: it cannot be "
               "set", var->name, reference);
        return BW_ERROR;
    }
}

static double bw_rate(bw_instance *inst, int a, int index);
static double bw_switch(bw_instance *inst, int a, int index);

static bw_status bw_get_real(bw_instance *inst, unsigned int reference, double *value) {
    const bw_variable *var;
    bw_axis *axis;
    if (reference >= BW_VARIABLES) {
        bw_log(inst, BW_ERROR, "logStatusError", "value reference %u does not exist (this FMU has 0 to %d)",
               reference, BW_VARIABLES - 1);
        return BW_ERROR;
    }
    var = &bw_variables[reference];
    axis = &inst->data.axes[var->axis];
    switch (var->kind) {
    case BW_PARAMETER: *value = axis->parameters[var->index]; break;
    case BW_DISPLACEMENT: *value = axis->x; break;
    case BW_VELOCITY: *value = axis->v; break;
    case BW_OUTPUT: *value = bw_output(inst, var->axis); break;
    case BW_STATE:
        *value = (bw_axis_group[var->axis] >= 0 ? inst->data.groups[bw_axis_group[var->axis]].state[var->index]
                                                 : axis->state[var->index]) * var->scale;
        break;
    case BW_DERIVATIVE: *value = bw_rate(inst, var->axis, var->index) * var->scale; break;
    case BW_INDICATOR: *value = bw_switch(inst, var->axis, var->index) * var->scale; break;
    case BW_TIME: *value = inst->data.time; break;
    }
    return BW_OK;
}

/* ------------------------------------------------------------------------------- co-simulation */

static bw_status bw_refuse(bw_instance *inst, const char *format, ...) {
    char message[BW_MESSAGE];
    va_list arguments;
    va_start(arguments, format);
    vsnprintf(message, sizeof message, format, arguments);
    va_end(arguments);
    bw_error(inst, "%s", message);
    return BW_DISCARD;
}

/* Axis a's inputs in port units (BW_TEXT_INPUTS) appended to text, after ", " if it holds some. */
static void bw_append_inputs(const bw_instance *inst, int a, char *text, size_t size) {
    const bw_axis_spec *spec = &bw_axis_specs[a];
    const bw_axis *axis = &inst->data.axes[a];
    size_t used = strlen(text);
    char x[40], v[40];
    bw_format_double(x, sizeof x, axis->x);
    bw_format_double(v, sizeof v, axis->v);
    if (used) snprintf(text + used, size - used, ", ");
    used = strlen(text);
    snprintf(text + used, size - used, BW_TEXT_INPUTS, spec->displacement, x, spec->rotational ? "rad" : "m",
             spec->velocity, v, spec->rotational ? "rad/s" : "m/s");
}

/* Every member's inputs of group g, as bw_append_inputs writes them. */
static void bw_group_inputs_text(const bw_instance *inst, int g, char *text, size_t size) {
    int c;
    text[0] = '\0';
    for (c = 0; c < bw_group_specs[g].members; c++) bw_append_inputs(inst, bw_group_specs[g].axis[c], text, size);
}

/* Record whether axis a's step starts with a displacement jump (BW_DISPLACEMENT_JUMPED: the test
   integration.displacement_jumped, translated; before the step is committed) and warn, once per
   instance, when more than BW_JUMP_COUNT of its last BW_JUMP_WINDOW steps do (as pythonfmu_slave.py does). */
static void bw_count_jump(bw_instance *inst, int a, double current_time, double h) {
    const bw_axis_spec *spec = &bw_axis_specs[a];
    const bw_axis *axis = &inst->data.axes[a];
    double mismatch = fabs(axis->x_now - axis->state_x);
    double travel = fabs(axis->v * spec->to_kernel) * h;
    int jumped = BW_DISPLACEMENT_JUMPED(axis->x_now, axis->state_x, axis->v * spec->to_kernel, h);
    unsigned long long bits;
    int count = 0;
    inst->jump_history[a] = ((inst->jump_history[a] << 1) | (unsigned long long)jumped)
                            & ((1ULL << BW_JUMP_WINDOW) - 1ULL);
    if (!jumped) return;
    for (bits = inst->jump_history[a]; bits; bits &= bits - 1ULL) count++;
    if (count > BW_JUMP_COUNT) {
        const char *unit = spec->rotational ? "rad" : "m";
        inst->jump_warned = 1;
        BW_MESSAGE_DISPLACEMENT_JUMPS(inst, spec->label, spec->displacement, count, BW_JUMP_WINDOW, current_time,
                                      mismatch / spec->to_kernel, unit, spec->velocity, travel / spec->to_kernel);
    }
}

/* One communication step of every axis; a step that cannot succeed on any axis is refused
   (BW_DISCARD) and leaves every axis as it was. */
static bw_status bw_do_step(bw_instance *inst, double current_time, double h) {
    double states[BW_AXES][BW_MAX_STATES], x_end[BW_AXES], outputs[BW_AXES];
    double group_states[BW_GROUP_SLOTS][BW_MAX_GROUP_STATES], group_x_end[BW_GROUP_SLOTS][3];
    char t_text[40], h_text[40], inputs[BW_MESSAGE];   /* formatted only for a message: the step's hot path does no text */
    int a, g;
    if (!(h > 0.0 && h < HUGE_VAL)) {
        bw_format_double(h_text, sizeof h_text, h);
        return BW_MESSAGE_STEP_SIZE_INVALID(inst, h_text);
    }
    if (!bw_check_parameters(inst)) {
        if (inst->data.initial_state_pending) {
            BW_MESSAGE_CANNOT_START(inst, BW_TEXT_PARAMETERS_INVALID);
            return BW_ERROR;
        }
        return BW_MESSAGE_STEP_PARAMETERS_INVALID(inst, BW_TEXT_PARAMETERS_INVALID);
    }
    for (a = 0; a < BW_AXES; a++) {
        const bw_axis_spec *spec = &bw_axis_specs[a];
        bw_axis *axis = &inst->data.axes[a];
        char value[40];
        if (!isfinite(axis->x)) {
            bw_format_double(value, sizeof value, axis->x);
            return BW_MESSAGE_STEP_INPUT_NOT_FINITE(inst, spec->displacement, value, spec->rotational ? "rad" : "m");
        }
        if (!isfinite(axis->v)) {
            bw_format_double(value, sizeof value, axis->v);
            return BW_MESSAGE_STEP_INPUT_NOT_FINITE(inst, spec->velocity, value, spec->rotational ? "rad/s" : "m/s");
        }
    }
    if (inst->data.initial_state_pending) bw_set_initial_state(inst);
    for (a = 0; a < BW_AXES; a++) {   /* every axis and group first, then commit all */
        const bw_axis_spec *spec = &bw_axis_specs[a];
        bw_axis *axis = &inst->data.axes[a];
        double x = axis->x_now, v = axis->v * spec->to_kernel;
        int status;
        if (bw_axis_group[a] >= 0) continue;     /* stepped with its group below */
        memcpy(states[a], axis->state, sizeof states[a]);
        status = spec->model->step(&axis->constants, states[a], axis->state_x, x, v, h, BW_MAX_SUBSTEPS);
        if (status != BW_KERNEL_OK) {
            bw_format_double(t_text, sizeof t_text, current_time);
            inputs[0] = '\0';
            bw_append_inputs(inst, a, inputs, sizeof inputs);
        }
        if (status == BW_KERNEL_TOO_MANY_SUBSTEPS) {
            return BW_MESSAGE_STEP_TOO_MANY_SUBSTEPS(inst, t_text, spec->label, h, BW_MAX_SUBSTEPS, inputs);
        }
        if (status != BW_KERNEL_OK) return BW_MESSAGE_STEP_NOT_FINITE(inst, t_text, spec->label, inputs);
        x_end[a] = x + v * h;
        outputs[a] = spec->model->force(&axis->constants, states[a], x_end[a], v) * spec->from_kernel
                     + bw_preload(axis, spec->model) * spec->from_kernel;
        if (!isfinite(outputs[a])) {
            bw_format_double(t_text, sizeof t_text, current_time);
            inputs[0] = '\0';
            bw_append_inputs(inst, a, inputs, sizeof inputs);
            return BW_MESSAGE_STEP_OUTPUT_NOT_FINITE(inst, t_text, spec->label, spec->output, outputs[a],
                                                     spec->rotational ? "N.m" : "N", inputs);
        }
    }
    for (g = 0; g < BW_GROUPS; g++) {
        const bw_group_spec *group = &bw_group_specs[g];
        const bw_coupled_model *kernels = bw_group_kernels(g);
        const void *constants = bw_group_constants(inst, g);
        double x[3], v[3], force[3];
        int c, status;
        bw_group_inputs(inst, g, x, v);
        memcpy(group_states[g], inst->data.groups[g].state, sizeof group_states[g]);
        status = kernels->step(constants, group_states[g], inst->data.groups[g].state_x, x, v, h, BW_MAX_SUBSTEPS);
        if (status != BW_KERNEL_OK) {
            bw_format_double(t_text, sizeof t_text, current_time);
            bw_group_inputs_text(inst, g, inputs, sizeof inputs);
        }
        if (status == BW_KERNEL_TOO_MANY_SUBSTEPS) {
            return BW_MESSAGE_STEP_TOO_MANY_SUBSTEPS(inst, t_text, group->label, h, BW_MAX_SUBSTEPS, inputs);
        }
        if (status != BW_KERNEL_OK) return BW_MESSAGE_STEP_NOT_FINITE(inst, t_text, group->label, inputs);
        for (c = 0; c < 3; c++) group_x_end[g][c] = x[c] + v[c] * h;
        kernels->force(constants, group_states[g], group_x_end[g], v, force);
        for (c = 0; c < group->members; c++) {
            const bw_axis_spec *spec = &bw_axis_specs[group->axis[c]];
            a = group->axis[c];
            x_end[a] = group_x_end[g][c];
            outputs[a] = force[c] * spec->from_kernel + bw_preload(&inst->data.axes[a], spec->model) * spec->from_kernel;
            if (!isfinite(outputs[a])) {
                bw_format_double(t_text, sizeof t_text, current_time);
                bw_group_inputs_text(inst, g, inputs, sizeof inputs);
                return BW_MESSAGE_STEP_OUTPUT_NOT_FINITE(inst, t_text, group->label, spec->output, outputs[a],
                                                         spec->rotational ? "N.m" : "N", inputs);
            }
        }
    }
    for (a = 0; a < BW_AXES; a++) {
        const bw_axis_spec *spec = &bw_axis_specs[a];
        bw_axis *axis = &inst->data.axes[a];
        if (fabs(outputs[a]) > axis->output_bound && !axis->output_warned) {
            axis->output_warned = 1;
            bw_format_double(t_text, sizeof t_text, current_time + h);
            inputs[0] = '\0';
            bw_append_inputs(inst, a, inputs, sizeof inputs);
            BW_MESSAGE_OUTPUT_IMPLAUSIBLE(inst, spec->output, outputs[a], spec->rotational ? "N.m" : "N", t_text,
                                          axis->output_bound,
                                          spec->rotational ? BW_TEXT_QUANTITY_ROTATIONAL : BW_TEXT_QUANTITY_TRANSLATIONAL,
                                          spec->rotational ? BW_TEXT_MOTION_ROTATIONAL : BW_TEXT_MOTION_TRANSLATIONAL,
                                          inputs, spec->rotational ? BW_TEXT_UNITS_ROTATIONAL : BW_TEXT_UNITS_TRANSLATIONAL);
        }
        if (!inst->jump_warned) bw_count_jump(inst, a, current_time, h);
        if (bw_axis_group[a] < 0) memcpy(axis->state, states[a], sizeof axis->state);
        axis->state_x = axis->x_now = x_end[a];
        axis->last_output = outputs[a];
        axis->output_is_current = 1;
    }
    for (g = 0; g < BW_GROUPS; g++) {
        memcpy(inst->data.groups[g].state, group_states[g], sizeof group_states[g]);
        memcpy(inst->data.groups[g].state_x, group_x_end[g], sizeof group_x_end[g]);
    }
    inst->data.time = current_time + h;
    return BW_OK;
}

/* ------------------------------------------------------------------------------- model exchange
   The host integrates the states: the continuous-state vector is every axis's states in the
   order the FMU names them (its variables), in port units (m or rad, N or N.m). */

static double bw_rate(bw_instance *inst, int a, int index) {
    const bw_axis_spec *spec = &bw_axis_specs[a];
    bw_axis *axis = &inst->data.axes[a];
    double rates[BW_MAX_STATES];
    int g = bw_axis_group[a];
    if (g >= 0) {    /* a coupled group's state: index into its flat state */
        double group_rates[BW_MAX_GROUP_STATES], x[3], v[3];
        if (!inst->data.groups[g].usable) return 0.0;
        bw_group_inputs(inst, g, x, v);
        bw_group_kernels(g)->derivatives(bw_group_constants(inst, g), inst->data.groups[g].state, x, v, group_rates);
        return group_rates[index];
    }
    if (!axis->usable) return 0.0;
    spec->model->derivatives(&axis->constants, axis->state, axis->x_now, axis->v * spec->to_kernel, rates);
    return rates[index];
}

static double bw_switch(bw_instance *inst, int a, int index) {
    const bw_axis_spec *spec = &bw_axis_specs[a];
    bw_axis *axis = &inst->data.axes[a];
    double values[BW_MAX_SWITCHES];
    int g = bw_axis_group[a];
    if (g >= 0) {    /* a coupled group's switches (its first member's indicators) */
        double group_values[BW_MAX_GROUP_SWITCHES], x[3], v[3];
        if (!inst->data.groups[g].usable) return 0.0;
        bw_group_inputs(inst, g, x, v);
        bw_group_kernels(g)->switch_values(bw_group_constants(inst, g), inst->data.groups[g].state, x, v,
                                           group_values);
        return group_values[index];
    }
    if (!axis->usable) return 0.0;
    spec->model->switch_values(&axis->constants, axis->state, axis->x_now, axis->v * spec->to_kernel, values);
    return values[index];
}

/* The change of the axes' states at an event (the models' update kernel: a friction element's
   reversal where the velocity has changed sign); 1 if any state changes. With apply = 0 it only
   tells (fmi?CompletedIntegratorStep asks for event mode then). */
static int bw_update_discrete_states(bw_instance *inst, int apply) {
    int a, changed = 0;
    if (!inst->model_exchange || !bw_check_parameters(inst)) return 0;
    for (a = 0; a < BW_AXES; a++) {
        const bw_axis_spec *spec = &bw_axis_specs[a];
        bw_axis *axis = &inst->data.axes[a];
        double state[BW_MAX_STATES];
        if (bw_axis_group[a] >= 0) continue;
        memcpy(state, axis->state, sizeof state);
        if (spec->model->update(&axis->constants, state, axis->x_now, axis->v * spec->to_kernel)) {
            changed = 1;
            if (!apply) return 1;
            memcpy(axis->state, state, sizeof axis->state);
            axis->output_is_current = 0;
        }
    }
    for (a = 0; a < BW_GROUPS; a++) {
        bw_group *group = &inst->data.groups[a];
        double state[BW_MAX_GROUP_STATES], x[3], v[3];
        int c;
        memcpy(state, group->state, sizeof state);
        bw_group_inputs(inst, a, x, v);
        if (bw_group_kernels(a)->update(bw_group_constants(inst, a), state, x, v)) {
            changed = 1;
            if (!apply) return 1;
            memcpy(group->state, state, sizeof group->state);
            for (c = 0; c < bw_group_specs[a].members; c++) inst->data.axes[bw_group_specs[a].axis[c]].output_is_current = 0;
        }
    }
    return changed;
}

static bw_status bw_wrong_count(bw_instance *inst, const char *what, size_t count, int expected) {
    bw_log(inst, BW_ERROR, "logStatusError", "%s %lu values: this FMU has %d", what, (unsigned long)count, expected);
    return BW_ERROR;
}

static bw_status bw_get_continuous_states(bw_instance *inst, double *values, size_t count) {
    size_t k = 0;
    int i;
    if (count != BW_CONTINUOUS_STATES) return bw_wrong_count(inst, "continuous states: asked for", count, BW_CONTINUOUS_STATES);
    for (i = 0; i < BW_VARIABLES && k < count; i++) {
        const bw_variable *var = &bw_variables[i];
        int g = bw_axis_group[var->axis];
        if (var->kind != BW_STATE) continue;
        values[k++] = (g >= 0 ? inst->data.groups[g].state[var->index] : inst->data.axes[var->axis].state[var->index])
                      * var->scale;
    }
    return BW_OK;
}

static bw_status bw_set_continuous_states(bw_instance *inst, const double *values, size_t count) {
    size_t k = 0;
    int i;
    if (count != BW_CONTINUOUS_STATES) return bw_wrong_count(inst, "continuous states: given", count, BW_CONTINUOUS_STATES);
    for (i = 0; i < BW_VARIABLES && k < count; i++) {
        const bw_variable *var = &bw_variables[i];
        bw_axis *axis = &inst->data.axes[var->axis];
        int g = bw_axis_group[var->axis];
        if (var->kind != BW_STATE) continue;
        if (g >= 0) {
            double v[3];
            inst->data.groups[g].state[var->index] = values[k++] / var->scale;
            bw_group_inputs(inst, g, inst->data.groups[g].state_x, v);   /* it belongs to the inputs set */
        } else {
            axis->state[var->index] = values[k++] / var->scale;
        }
        axis->state_x = axis->x_now;      /* the host's state belongs to the inputs it set */
        bw_inputs_changed(inst, var->axis);
    }
    return BW_OK;
}

static bw_status bw_derivatives(bw_instance *inst, double *values, size_t count) {
    size_t k = 0;
    int i;
    if (count != BW_CONTINUOUS_STATES) return bw_wrong_count(inst, "derivatives: asked for", count, BW_CONTINUOUS_STATES);
    if (!bw_check_parameters(inst)) {
        BW_MESSAGE_NOT_COMPUTABLE(inst, "", "derivatives", BW_TEXT_PARAMETERS_INVALID);
        return BW_ERROR;
    }
    for (i = 0; i < BW_VARIABLES && k < count; i++) {
        const bw_variable *var = &bw_variables[i];
        if (var->kind != BW_STATE) continue;
        values[k] = bw_rate(inst, var->axis, var->index) * var->scale;
        if (!isfinite(values[k])) {
            BW_MESSAGE_DERIVATIVE_NOT_FINITE(inst, "", var->name, values[k]);
            return BW_ERROR;
        }
        k++;
    }
    return BW_OK;
}

static bw_status bw_event_indicators(bw_instance *inst, double *values, size_t count) {
    size_t k = 0;
    int i;
    if (count != BW_EVENT_INDICATORS) return bw_wrong_count(inst, "event indicators: asked for", count, BW_EVENT_INDICATORS);
    if (!bw_check_parameters(inst)) {
        BW_MESSAGE_NOT_COMPUTABLE(inst, "", "event indicators", BW_TEXT_PARAMETERS_INVALID);
        return BW_ERROR;
    }
    for (i = 0; i < BW_VARIABLES && k < count; i++) {
        const bw_variable *var = &bw_variables[i];
        if (var->kind == BW_INDICATOR) values[k++] = bw_switch(inst, var->axis, var->index) * var->scale;
    }
    return BW_OK;
}

static void bw_nominals(double *values, size_t count) {
    size_t k = 0;
    int i;
    for (i = 0; i < BW_VARIABLES && k < count; i++) {
        if (bw_variables[i].kind == BW_STATE) values[k++] = bw_nominal[i];
    }
}

/* ------------------------------------------------------------------------------- directional derivatives
   The Jacobian of the unknowns (the outputs, and in model exchange the states' derivatives) with
   respect to the knowns (the inputs, and in model exchange the states) at the current inputs and
   state, in port units, from the tangents generated from the kernels (fmu_src/kernels/tangents.py: exact
   to rounding where the kernels are smooth, a stated one-sided value where they switch). The
   axes are independent, so the Jacobian is block diagonal: one tangent per axis and direction.
   In co-simulation the output is the one bw_output returns, the committed state taken through
   the displacement jump to x (which the dashpots carry): dF/dx includes the jump's derivative,
   also where x equals the committed state's displacement. There (a jump of 0, or of rounding
   size: BW_ROUNDING_JUMP, integration.ROUNDING_JUMP_MM) F is not differentiable where the
   motion could reverse (a Bouc-Wen walk's sgn, a friction element's turn), and the derivative
   is the one-sided one in the direction of the velocity set, the branch the motion continues
   on, taken at a jump of twice the rounding size that way (the kernels' own choice at exactly 0
   is the reversal's for some and the continuation's for others, and rounding of the host's x
   would pick between them at random). Available from the exit of initialization mode (the
   state is set there). */

typedef struct {
    double d_state[BW_MAX_STATES];   /* kernel units */
    double dx, dv;                   /* kernel units */
} bw_direction;

static bw_status bw_derivative_refused(bw_instance *inst, const char *function, const char *role, unsigned int reference,
                                       const char *allowed) {
    if (reference >= BW_VARIABLES) {
        bw_log(inst, BW_ERROR, "logStatusError", "%s: the %s value reference %u does not exist (this FMU has 0 to %d)",
               function, role, reference, BW_VARIABLES - 1);
    } else {
        bw_log(inst, BW_ERROR, "logStatusError", "%s: %s (value reference %u) cannot be a%s %s: %s", function,
               bw_variables[reference].name, reference, role[0] == 'u' ? "n" : "", role, allowed);
    }
    return BW_ERROR;
}

/* Unknowns must be outputs (or, in model exchange, states' derivatives), knowns inputs (or, in
   model exchange, states); the parameters must be usable. */
static bw_status bw_check_derivative_variables(bw_instance *inst, const char *function, const unsigned int unknowns[],
                                               size_t n_unknowns, const unsigned int knowns[], size_t n_knowns) {
    const char *unknown_rule = inst->model_exchange ? "the unknowns are outputs and states' derivatives"
                                                    : "in co-simulation the unknowns are the outputs";
    const char *known_rule = inst->model_exchange ? "the knowns are inputs and continuous states"
                                                  : "in co-simulation the knowns are the inputs";
    size_t i;
    if (!inst->initialized) {
        bw_log(inst, BW_ERROR, "logStatusError", "%s: the derivatives are available after the exit of initialization "
               "mode, where the state is set", function);
        return BW_ERROR;
    }
    for (i = 0; i < n_unknowns; i++) {
        unsigned int r = unknowns[i];
        if (r >= BW_VARIABLES || !(bw_variables[r].kind == BW_OUTPUT ||
                                   (inst->model_exchange && bw_variables[r].kind == BW_DERIVATIVE))) {
            return bw_derivative_refused(inst, function, "unknown", r, unknown_rule);
        }
    }
    for (i = 0; i < n_knowns; i++) {
        unsigned int r = knowns[i];
        if (r >= BW_VARIABLES || !(bw_variables[r].kind == BW_DISPLACEMENT || bw_variables[r].kind == BW_VELOCITY ||
                                   (inst->model_exchange && bw_variables[r].kind == BW_STATE))) {
            return bw_derivative_refused(inst, function, "known", r, known_rule);
        }
    }
    if (!bw_check_parameters(inst)) {
        char where[80];
        snprintf(where, sizeof where, "%s: ", function);
        BW_MESSAGE_NOT_COMPUTABLE(inst, where, "derivatives", BW_TEXT_PARAMETERS_INVALID);
        return BW_ERROR;
    }
    return BW_OK;
}

/* Add a known's seed (port units) to its axis's direction (kernel units). */
static void bw_seed(bw_direction *direction, unsigned int known, double seed) {
    const bw_variable *var = &bw_variables[known];
    const bw_axis_spec *spec = &bw_axis_specs[var->axis];
    switch (var->kind) {
    case BW_DISPLACEMENT: direction->dx += seed * spec->to_kernel; break;
    case BW_VELOCITY: direction->dv += seed * spec->to_kernel; break;
    case BW_STATE: direction->d_state[var->index] += seed / var->scale; break;
    default: break;
    }
}

/* Axis a's output and states' derivatives in a direction: d_output in port units, d_rates in
   kernel units (NULL: not wanted). */
static bw_status bw_axis_tangent(bw_instance *inst, const char *function, int a, const bw_direction *direction,
                                 double *d_output, double *d_rates) {
    const bw_axis_spec *spec = &bw_axis_specs[a];
    bw_axis *axis = &inst->data.axes[a];
    const bw_model *model = spec->model;
    double state[BW_MAX_STATES], d_state[BW_MAX_STATES], v = axis->v * spec->to_kernel;
    int i;
    memcpy(state, axis->state, sizeof state);
    memcpy(d_state, direction->d_state, sizeof d_state);
    if (!isfinite(axis->x_now) || !isfinite(v)) {
        bw_log(inst, BW_ERROR, "logStatusError", "%s: %sthe inputs %s, %s are not finite numbers", function,
               spec->label, spec->displacement, spec->velocity);
        return BW_ERROR;
    }
    if (!inst->model_exchange) {
        double d_jump[BW_MAX_STATES], jump = axis->x_now - axis->state_x;
        if (fabs(jump) <= BW_ROUNDING_JUMP && v != 0.0) jump = copysign(2.0 * BW_ROUNDING_JUMP, v);
        if (model->jump_tangent(&axis->constants, state, jump, d_jump) != BW_KERNEL_OK) {
            char where[80];
            snprintf(where, sizeof where, "%s: ", function);
            BW_MESSAGE_JUMP_NOT_DIFFERENTIABLE(inst, where, spec->label, spec->output, spec->displacement);
            return BW_ERROR;
        }
        for (i = 0; i < model->states; i++) d_state[i] = d_jump[i] * direction->dx;
    }
    *d_output = model->force_tangent(&axis->constants, state, axis->x_now, v, d_state, direction->dx, direction->dv)
                * spec->from_kernel;
    if (!isfinite(*d_output)) {
        char where[80];
        snprintf(where, sizeof where, "%s: ", function);
        BW_MESSAGE_DERIVATIVE_NOT_FINITE(inst, where, spec->output, *d_output);
        return BW_ERROR;
    }
    if (d_rates) {
        model->derivatives_tangent(&axis->constants, state, axis->x_now, v, d_state, direction->dx, direction->dv,
                                   d_rates);
        for (i = 0; i < model->states; i++) {
            if (!isfinite(d_rates[i])) {
                char where[80];
                snprintf(where, sizeof where, "%s: ", function);
                BW_MESSAGE_RATE_DERIVATIVE_NOT_FINITE(inst, where, spec->label, i, d_rates[i]);
                return BW_ERROR;
            }
        }
    }
    return BW_OK;
}

/* A coupled group's direction: its flat state's, and the members' inputs' as 3-vectors (kernel units). */
typedef struct {
    double d_state[BW_MAX_GROUP_STATES];
    double dx[3], dv[3];
} bw_group_direction;

/* Group g's members' outputs (port units) and its states' derivatives (kernel units, NULL: not
   wanted) in a direction, as bw_axis_tangent for one axis: in co-simulation through the jump from
   the committed state to the inputs, at no jump (of rounding size) a jump of twice that along the
   velocity, the side the motion continues on. */
static bw_status bw_group_tangent(bw_instance *inst, const char *function, int g, const bw_group_direction *direction,
                                  double *d_output, double *d_rates) {
    const bw_group_spec *spec = &bw_group_specs[g];
    const bw_group *group = &inst->data.groups[g];
    const bw_coupled_model *kernels = bw_group_kernels(g);
    const void *constants = bw_group_constants(inst, g);
    double state[BW_MAX_GROUP_STATES], d_state[BW_MAX_GROUP_STATES], x[3], v[3], d_force[3];
    int c, i;
    bw_group_inputs(inst, g, x, v);
    memcpy(state, group->state, sizeof state);
    memcpy(d_state, direction->d_state, sizeof d_state);
    for (c = 0; c < 3; c++) {
        if (!isfinite(x[c]) || !isfinite(v[c])) {
            bw_log(inst, BW_ERROR, "logStatusError", "%s: %sthe inputs are not finite numbers", function, spec->label);
            return BW_ERROR;
        }
    }
    if (!inst->model_exchange) {
        double jump[3], length = 0.0, speed = 0.0;
        for (c = 0; c < 3; c++) {
            jump[c] = x[c] - group->state_x[c];
            length += jump[c] * jump[c];
            speed += v[c] * v[c];
        }
        if (sqrt(length) <= BW_ROUNDING_JUMP && speed > 0.0) {
            for (c = 0; c < 3; c++) jump[c] = 2.0 * BW_ROUNDING_JUMP * v[c] / sqrt(speed);
        }
        if (kernels->jump_tangent(constants, state, jump, direction->dx, d_state) != BW_KERNEL_OK) {
            char where[80];
            snprintf(where, sizeof where, "%s: ", function);
            BW_MESSAGE_JUMP_NOT_DIFFERENTIABLE(inst, where, spec->label, "the outputs", "the inputs");
            return BW_ERROR;
        }
    }
    kernels->force_tangent(constants, state, x, v, d_state, direction->dx, direction->dv, d_force);
    for (c = 0; c < spec->members; c++) {
        const bw_axis_spec *member = &bw_axis_specs[spec->axis[c]];
        d_output[c] = d_force[c] * member->from_kernel;
        if (!isfinite(d_output[c])) {
            char where[80];
            snprintf(where, sizeof where, "%s: ", function);
            BW_MESSAGE_DERIVATIVE_NOT_FINITE(inst, where, member->output, d_output[c]);
            return BW_ERROR;
        }
    }
    if (d_rates) {
        kernels->derivatives_tangent(constants, state, x, v, d_state, direction->dx, direction->dv, d_rates);
        for (i = 0; i < kernels->states; i++) {
            if (!isfinite(d_rates[i])) {
                char where[80];
                snprintf(where, sizeof where, "%s: ", function);
                BW_MESSAGE_RATE_DERIVATIVE_NOT_FINITE(inst, where, spec->label, i, d_rates[i]);
                return BW_ERROR;
            }
        }
    }
    return BW_OK;
}

/* An unknown's value in its axis's tangent (port units). */
static double bw_unknown_tangent(unsigned int unknown, double d_output, const double *d_rates) {
    const bw_variable *var = &bw_variables[unknown];
    return var->kind == BW_OUTPUT ? d_output : d_rates[var->index] * var->scale;
}

/* fmi?GetDirectionalDerivative: sensitivity = J * seed (J: d unknowns / d knowns). */
static bw_status bw_directional_derivative(bw_instance *inst, const char *function, const unsigned int unknowns[],
                                           size_t n_unknowns, const unsigned int knowns[], size_t n_knowns,
                                           const double seed[], double sensitivity[]) {
    bw_direction directions[BW_AXES];
    bw_group_direction group_directions[BW_GROUP_SLOTS];
    double d_output[BW_AXES] = {0.0}, d_rates[BW_AXES][BW_MAX_STATES] = {{0.0}};
    double group_d_output[BW_GROUP_SLOTS][3] = {{0.0}}, group_d_rates[BW_GROUP_SLOTS][BW_MAX_GROUP_STATES] = {{0.0}};
    int wanted[BW_AXES] = {0}, group_wanted[BW_GROUP_SLOTS] = {0};
    size_t i;
    int a, g;
    bw_status status = bw_check_derivative_variables(inst, function, unknowns, n_unknowns, knowns, n_knowns);
    if (status != BW_OK) return status;
    memset(directions, 0, sizeof directions);
    memset(group_directions, 0, sizeof group_directions);
    for (i = 0; i < n_knowns; i++) {
        const bw_variable *var = &bw_variables[knowns[i]];
        g = bw_axis_group[var->axis];
        if (g < 0) {
            bw_seed(&directions[var->axis], knowns[i], seed[i]);
        } else if (var->kind == BW_DISPLACEMENT) {
            group_directions[g].dx[bw_axis_component[var->axis]] += seed[i] * bw_axis_specs[var->axis].to_kernel;
        } else if (var->kind == BW_VELOCITY) {
            group_directions[g].dv[bw_axis_component[var->axis]] += seed[i] * bw_axis_specs[var->axis].to_kernel;
        } else if (var->kind == BW_STATE) {
            group_directions[g].d_state[var->index] += seed[i] / var->scale;
        }
    }
    for (i = 0; i < n_unknowns; i++) {
        a = bw_variables[unknowns[i]].axis;
        if (bw_axis_group[a] >= 0) group_wanted[bw_axis_group[a]] = 1;
        else wanted[a] = 1;
    }
    for (a = 0; a < BW_AXES; a++) {
        if (!wanted[a]) continue;
        status = bw_axis_tangent(inst, function, a, &directions[a], &d_output[a],
                                 inst->model_exchange ? d_rates[a] : NULL);
        if (status != BW_OK) return status;
    }
    for (g = 0; g < BW_GROUPS; g++) {
        if (!group_wanted[g]) continue;
        status = bw_group_tangent(inst, function, g, &group_directions[g], group_d_output[g],
                                  inst->model_exchange ? group_d_rates[g] : NULL);
        if (status != BW_OK) return status;
    }
    for (i = 0; i < n_unknowns; i++) {
        const bw_variable *var = &bw_variables[unknowns[i]];
        a = var->axis;
        g = bw_axis_group[a];
        if (g < 0) {
            sensitivity[i] = bw_unknown_tangent(unknowns[i], d_output[a], d_rates[a]);
        } else {
            sensitivity[i] = var->kind == BW_OUTPUT ? group_d_output[g][bw_axis_component[a]]
                                                    : group_d_rates[g][var->index] * var->scale;
        }
    }
    return BW_OK;
}

/* ------------------------------------------------------------------------------- FMU state */

#define BW_STATE_MAGIC 0x42575346u   /* "BWSF" */

typedef struct {
    unsigned int magic;
    unsigned int size;
    bw_data data;
} bw_saved_state;

static size_t bw_serialized_size(void) { return sizeof(bw_saved_state); }

static void bw_save(const bw_instance *inst, bw_saved_state *saved) {
    saved->magic = BW_STATE_MAGIC;
    saved->size = (unsigned int)sizeof(bw_saved_state);
    saved->data = inst->data;
}

static bw_status bw_restore(bw_instance *inst, const bw_saved_state *saved) {
    if (saved->magic != BW_STATE_MAGIC || saved->size != sizeof(bw_saved_state)) {
        bw_error(inst, "%s", "the FMU state was not saved by this FMU (or by another build of it)");
        return BW_ERROR;
    }
    inst->data = saved->data;
    return BW_OK;
}
