/* Part of the native FMU's instance (bushing_instance.h).
   The instance's messages: a double written as Python's repr, logging by status and category, the
   categories a host enables (fmi2/fmi3SetDebugLogging). The words are runtime_messages.py's
   (bushing_messages.h). */

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
