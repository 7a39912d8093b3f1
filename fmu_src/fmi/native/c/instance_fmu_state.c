/* Part of the native FMU's instance (bushing_instance.h).
   FMU state: save, restore and serialize an instance's data. */
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
