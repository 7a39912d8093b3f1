/* Part of the native FMU's instance (bushing_instance.h).
   Co-simulation: one communication step of every axis and group, refused as a whole (BW_DISCARD,
   nothing changed) when any cannot be taken; the jumping-input count. */
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
