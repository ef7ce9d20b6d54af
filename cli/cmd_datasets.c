/* `tcbench datasets`: list and export the synthetic sequences; its align
 * and distortion actions are cli/datasets_align.c and
 * cli/datasets_distortion.c. */
#include <stdio.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/datasets.h"
#include "tcb/align.h"
#include "tcb/fsutil.h"
#include "tcb/sequence.h"
#include "tcb/synth.h"

static int synth_index(const char *name)
{
    for (int k = 0; k < tcb_synth_count(); k++)
        if (strcmp(tcb_synth_name(k), name) == 0) return k;
    return -1;
}

static int datasets_synth(const cli_args *c)
{
    if (!c->value[F_OUT]) return cli_usage_error("datasets synth", "%s is required", "--out DIR");
    const char *only = c->value[F_SEQUENCE];
    if (only && synth_index(only) < 0)
        return cli_usage_error("datasets synth", "no synthetic sequence named '%s'", only);
    for (int k = 0; k < tcb_synth_count(); k++) {
        const char *name = tcb_synth_name(k);
        if (only && strcmp(only, name) != 0) continue;
        tcb_error err = {0};
        tcb_sequence seq = {0};
        char dir[TCB_PATH_MAX];
        int rc = tcb_path_join(dir, sizeof dir, &err, "%s/%s", c->value[F_OUT], name);
        if (!rc) rc = tcb_synth_generate(name, (uint64_t)cli_flag_int(c, F_SEED, 0), (int)cli_flag_int(c, F_FRAMES, 0), &seq, &err);
        if (!rc) rc = tcb_sequence_write_objdir(&seq, dir, &err);
        if (!rc) fprintf(stderr, "wrote %s/ (%d frames, %d vertices)\n", dir, seq.n_frames, seq.n_verts);
        tcb_sequence_free(&seq);
        if (rc) return cli_fail(&err);
    }
    return 0;
}

static int datasets_align(const cli_args *c)
{
    if (c->n_args != 2) return cli_usage_error("datasets align", "missing %s", "DIR");
    if (!c->value[F_OUT]) return cli_usage_error("datasets align", "%s is required", "--out FILE");
    if (c->set[F_FRAMES] || c->set[F_SEQUENCE])
        return cli_usage_error("datasets align", "%s applies to 'datasets synth' only",
                           c->set[F_FRAMES] ? "--frames" : "--sequence");
    tcb_align_cmd a = {c->value[F_OUT], c->value[F_PLOT], (int)cli_flag_int(c, F_SAMPLES, TCB_ALIGN_DEFAULT_SAMPLES),
                       (uint64_t)cli_flag_int(c, F_SEED, 0)};
    tcb_error err = {0};
    if (tcb_datasets_align(c->arg[1], &a, &err)) return cli_fail(&err);
    fprintf(stderr, "wrote %s%s%s\n", a.out, a.plot ? " and " : "", a.plot ? a.plot : "");
    return 0;
}

static int datasets_distortion(const cli_args *c)
{
    if (c->n_args != 2) return cli_usage_error("datasets distortion", "missing %s", "NAME|DIR");
    for (int f = 0; f < F_COUNT; f++)
        if (f != F_PLUGIN && f != F_SEED && f != F_FRAMES && c->set[f])
            return cli_usage_error("datasets distortion", "%s does not apply", cli_flags[f].name);
    tcb_error err = {0};
    if (tcb_datasets_distortion(c->arg[1], (uint64_t)cli_flag_int(c, F_SEED, 0), (int)cli_flag_int(c, F_FRAMES, 0),
                                stdout, &err))
        return cli_fail(&err);
    return 0;
}

static int cmd_datasets(const cli_args *c)
{
    if (strcmp(c->arg[0], "align") == 0) return datasets_align(c);
    if (strcmp(c->arg[0], "distortion") == 0) return datasets_distortion(c);
    if (c->n_args > 1) return cli_usage_error("datasets", "unexpected argument '%s'", c->arg[1]);
    if (c->set[F_SAMPLES] || c->set[F_PLOT])
        return cli_usage_error("datasets", "%s applies to 'datasets align' only",
                           c->set[F_SAMPLES] ? "--samples" : "--plot");
    if (strcmp(c->arg[0], "synth") == 0) return datasets_synth(c);
    if (strcmp(c->arg[0], "list") != 0)
        return cli_usage_error("datasets", "unknown action '%s' (expected list, synth, align or distortion)", c->arg[0]);
    for (int f = 0; f < F_COUNT; f++)
        if (f != F_PLUGIN && c->set[f])
            return cli_usage_error("datasets list", "%s applies to 'datasets synth' only", cli_flags[f].name);
    for (int k = 0; k < tcb_synth_count(); k++)
        printf("%-20s %s\n", tcb_synth_name(k), tcb_synth_description(k));
    return 0;
}

const cli_command cli_datasets = {
    .name = "datasets", .fn = cmd_datasets, .min_args = 1, .max_args = 2, .arg_names = "ACTION (list, synth, align or distortion)",
    .accepts = BIT(F_OUT) | BIT(F_SEED) | BIT(F_FRAMES) | BIT(F_SEQUENCE) | BIT(F_SAMPLES) | BIT(F_PLOT),
    .summary = "list or export the synthetic sequences, align an OBJ sequence's rotations",
    .usage =
        "usage: tcbench datasets list\n"
        "       tcbench datasets synth --out DIR [--seed N] [--frames N] [--sequence NAME]\n"
        "       tcbench datasets align DIR --out FILE [--samples N] [--seed N] [--plot PNG]\n"
        "       tcbench datasets distortion NAME|DIR [--seed N] [--frames N]\n"
        "\n"
        "list:  the embedded synthetic sequences.\n"
        "synth: writes synthetic sequences as OBJ files, DIR/<name>/mesh_NNNN.obj\n"
        "       (raw coordinates, before normalization).\n"
        "align: the rotation alignment of an OBJ directory (AMA, paper 4.2): each frame,\n"
        "       centred, turned about y by the multiple of 3 degrees that minimises the\n"
        "       Chamfer distance to the aligned previous frame; writes the angles per\n"
        "       frame as JSON (what a config's \"align_rotation\": true applies).\n"
        "distortion: how far a synthetic sequence (NAME) or an OBJ directory is from\n"
        "       isometric: per frame against frame 0, the mean and max relative change\n"
        "       of edge lengths, the mean relative change of geodesic distances, the\n"
        "       area ratio (raw coordinates).\n"
        "\n"
        "options:\n"
        "  --out DIR|FILE   output directory (synth) or rotations file (align); required\n"
        "  --seed N         generator seed (synth), sample seed (align; a run uses its\n"
        "                   pool_seed); default 0\n"
        "  --frames N       frames per sequence (default: the sequence's own length)\n"
        "  --sequence NAME  only this sequence (default: all)\n"
        "  --samples N      align: points per frame for the Chamfer (default 1000)\n"
        "  --plot PNG       align: also plot the angle per frame\n"
        "\n"
        "examples:\n"
        "  tcbench datasets synth --out data/synth --sequence quadruped_walk\n"
        "  tcbench datasets align ../shared/data/ama/crane --out crane-rotations.json --plot crane-yaw.png\n"
        "  tcbench datasets distortion quadruped_collapse\n"
};
