/* Part of the native FMU's instance (bushing_instance.h).
   Life cycle: a new instance, reset, the exit of initialization mode (start values that cannot run
   are an error, each named) and the initial state: relaxed, or holding a force at rest. */
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

/* Each axis alone relaxed at its displacement, holding its held force beyond that where it is not
   0 (BushingModel.holding_state: the relaxed state, its force at rest, the resting state of that
   plus the held force); each coupled group relaxed at its members' displacement vector. */
static void bw_set_initial_state(bw_instance *inst) {
    int a, g;
    for (a = 0; a < BW_AXES; a++) {
        bw_axis *axis = &inst->data.axes[a];
        const bw_model *model = bw_axis_specs[a].model;
        if (bw_axis_group[a] < 0) {
            model->initial_state(&axis->constants, axis->x_now, axis->state);
            if (model->held >= 0 && axis->parameters[model->held] != 0.0) {
                double relaxed = model->force(&axis->constants, axis->state, axis->x_now, 0.0);
                model->resting_state(&axis->constants, axis->x_now, relaxed + axis->parameters[model->held],
                                     axis->state);
            }
        }
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
