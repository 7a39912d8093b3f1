/* Part of the native FMU's instance (bushing_instance.h). Directional derivatives:
   the Jacobian of the unknowns (the outputs, and in model exchange the states' derivatives) with
   respect to the knowns (the inputs, and in model exchange the states) at the current inputs and
   state, in port units, from the tangents generated from the kernels (fmu_src/kernels/tangents.py: exact
   to rounding where the kernels are smooth, a stated one-sided value where they switch). The
   axes are independent, so the Jacobian is block diagonal: one tangent per axis and direction.
   In co-simulation the output is the one bw_output returns, the committed state taken through
   the displacement jump to x (which the dashpots carry): dF/dx includes the jump's derivative,
   also where x equals the committed state's displacement. There (a jump of 0, or of rounding
   size: BW_ROUNDING_JUMP, elements.ROUNDING_JUMP_MM) F is not differentiable where the
   motion could reverse (a Bouc-Wen walk's sgn, a friction element's turn), and the derivative
   is the one-sided one in the direction of the velocity set, the branch the motion continues
   on, taken at a jump of twice the rounding size that way (the kernels' own choice at exactly 0
   is the reversal's for some and the continuation's for others, and rounding of the host's x
   would pick between them at random). Available from the exit of initialization mode (the
   state is set there). */

/* BW_OK if each of the count derivatives of the states' rates is finite; else BW_ERROR, naming
   the first that is not (in function, for the axis or group that label names). */
static bw_status bw_rates_finite(bw_instance *inst, const char *function, const char *label, const double *d_rates,
                                 int count) {
    char where[80];
    int i;
    for (i = 0; i < count; i++) {
        if (!isfinite(d_rates[i])) {
            snprintf(where, sizeof where, "%s: ", function);
            BW_MESSAGE_RATE_DERIVATIVE_NOT_FINITE(inst, where, label, i, d_rates[i]);
            return BW_ERROR;
        }
    }
    return BW_OK;
}

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
        return bw_rates_finite(inst, function, spec->label, d_rates, model->states);
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
    int c;
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
        return bw_rates_finite(inst, function, spec->label, d_rates, kernels->states);
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
