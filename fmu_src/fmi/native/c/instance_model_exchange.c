/* Part of the native FMU's instance (bushing_instance.h).
   Model exchange: the host integrates the states; the continuous-state vector is every axis's
   states in the order the FMU names them (its variables), in port units (m or rad, N or N.m). */

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
