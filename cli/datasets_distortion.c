/* `tcbench datasets distortion NAME|DIR`: how far a sequence is from
 * isometric, frame by frame (tcb/distortion.h), for a synthetic sequence
 * or an OBJ directory, on its raw coordinates. It is how docs/datasets.md
 * compares the generator's collapse with the real sequences. */
#include <stdlib.h>
#include <string.h>

#include "cli/datasets.h"
#include "datasets/objdir.h"
#include "tcb/distortion.h"
#include "tcb/fsutil.h"
#include "tcb/synth.h"

static int load(const char *what, uint64_t seed, int n_frames, tcb_sequence *s, tcb_error *err)
{
    for (int k = 0; k < tcb_synth_count(); k++)
        if (strcmp(tcb_synth_name(k), what) == 0) return tcb_synth_generate(what, seed, n_frames, s, err);
    if (!tcb_is_dir(what))
        return tcb_fail(err, TCB_ERR_INPUT,
                        "%s: neither a synthetic sequence ('tcbench datasets list') nor a directory",
                        what);
    tcb_objdir_frame *files;
    int n;
    char name[TCB_NAME_MAX];
    int rc = tcb_objdir_list(what, &files, &n, err);
    if (rc) return rc;
    rc = tcb_objdir_default_name(what, name, err);
    if (!rc) rc = tcb_objdir_read(what, files, n, name, s, err);
    free(files);
    return rc;
}

static void print_table(const tcb_sequence *s, const tcb_distortion *d, FILE *out)
{
    fprintf(out, "%s: %d frames, %d vertices; against frame 0 (|l_f/l_0 - 1| over edges, "
            "|g_f/g_0 - 1| over geodesics from %d sources)\n",
            s->name, s->n_frames, s->n_verts, TCB_DISTORTION_SOURCES);
    fprintf(out, "%6s %11s %10s %10s %6s\n", "frame", "edges mean", "edges max", "geodesics",
            "area");
    for (int f = 0; f < s->n_frames; f++)
        fprintf(out, "%6d %10.1f%% %9.1f%% %9.1f%% %6.3f\n", f, 100.0 * d[f].edge_mean,
                100.0 * d[f].edge_max, 100.0 * d[f].geo_mean, d[f].area_ratio);
}

int tcb_datasets_distortion(const char *what, uint64_t seed, int n_frames, FILE *out, tcb_error *err)
{
    tcb_sequence s = {0};
    tcb_distortion *d = NULL;
    int rc = load(what, seed, n_frames, &s, err);
    if (!rc && !(d = calloc((size_t)s.n_frames, sizeof *d)))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", what);
    if (!rc) rc = tcb_sequence_distortion(&s, d, err);
    if (!rc) print_table(&s, d, out);
    free(d);
    tcb_sequence_free(&s);
    return rc;
}
