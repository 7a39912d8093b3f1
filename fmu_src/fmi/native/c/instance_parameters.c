/* Part of the native FMU's instance (bushing_instance.h).
   Parameters: the mounting, each axis's parameters checked against its model's rules (and its
   plausible-force bound), a coupled group's members' parameters checked to be one set. */
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
   model's zero parameters 0 (Spencer's x0) and their held forces at rest 0; logs every difference, naming the group, the axes and
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
    for (c = 0; model->held >= 0 && c < spec->members; c++) {     /* a group starts relaxed */
        double held = inst->data.axes[spec->axis[c]].parameters[model->held];
        if (held == 0.0) continue;
        bw_format_double(a, sizeof a, held);
        BW_MESSAGE_GROUP_HELD_FORCE_NOT_ZERO(inst, spec->label, bw_axis_specs[spec->axis[c]].name, a,
                                             model->specs[model->held].unit);
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
