/* Part of the native FMU's instance (bushing_instance.h).
   Variables: setting parameters and inputs (with their warnings), the outputs at the current inputs
   (never NaN), getting and setting by value reference. */
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
