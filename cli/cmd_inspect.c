/* `tcbench inspect` and `frames`: one evaluation pair of a cell, and a few
 * of its frames, as pictures and meshes. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "tcb/frames.h"
#include "tcb/inspect.h"
#include "tcb/progress.h"

static int cmd_inspect(const cli_args *c)
{
    long long pair = -1;
    if (strcmp(c->arg[2], "worst") != 0) {
        char *end;
        errno = 0;
        pair = strtoll(c->arg[2], &end, 10);
        if (!*c->arg[2] || *end || errno || pair < 0 || pair > 1000000000)
            return cli_usage_error("inspect", "PAIR: expected a pair index or 'worst', got '%s'",
                               c->arg[2]);
    }
    tcb_term_progress tp;
    tcb_term_progress_init(&tp, stderr, c->set[F_QUIET] ? 1 : -1);
    tcb_inspect_opts o = {c->arg[0], c->arg[1], (int)pair, (int)cli_flag_int(c, F_SEED, -1), c->value[F_SEQUENCE],
                          c->value[F_OUT], (int)cli_flag_int(c, F_THREADS, 0), tcb_term_progress_reporter(&tp)};
    tcb_error err = {0};
    char dir[TCB_PATH_MAX];
    int rc = tcb_inspect(&o, stdout, dir, &err);
    tcb_term_progress_finish(&tp);
    if (rc) return cli_fail(&err);
    fprintf(stderr, "files: %s/\n", dir);
    return 0;
}

/* "0,8,16": distinct checks are the library's, which knows the sequence. */
static int frame_list(const char *s, int *frames, int *n)
{
    *n = 0;
    for (const char *p = s;; p++) {
        char *end;
        errno = 0;
        long v = strtol(p, &end, 10);
        if (end == p || errno || v < 0 || v > 1000000000 || (*end && *end != ',') || *n == TCB_FRAMES_MAX)
            return cli_usage_error("frames", "--frames: expected up to %d frame numbers separated by commas, got '%s'",
                               TCB_FRAMES_MAX, s);
        frames[(*n)++] = (int)v;
        if (!*end) return 0;
        p = end;
    }
}

static int frames_style(const char *s, tcb_frames_style *style)
{
    static const char *const names[] = {"auto", "texture", "transfer"}; /* tcb_frames_style */
    for (int k = 0; k < 3; k++)
        if (strcmp(s ? s : "auto", names[k]) == 0) return *style = (tcb_frames_style)k, 0;
    return cli_usage_error("frames", "--style: expected auto, texture or transfer, got '%s'", s);
}

static int cmd_frames(const cli_args *c)
{
    int frames[TCB_FRAMES_MAX], n = 0;
    tcb_frames_style style = TCB_FRAMES_AUTO;
    if (c->set[F_FRAMES] && c->set[F_N_FRAMES]) return cli_usage_error("frames", "--frames and --count exclude each other");
    if (c->set[F_FRAMES] && frame_list(c->value[F_FRAMES], frames, &n)) return 2;
    if (frames_style(c->value[F_STYLE], &style)) return 2;
    tcb_term_progress tp;
    tcb_term_progress_init(&tp, stderr, c->set[F_QUIET] ? 1 : -1);
    tcb_frames_opts o = {c->arg[0], c->arg[1], n ? frames : NULL, n, (int)cli_flag_int(c, F_N_FRAMES, 0),
                         (int)cli_flag_int(c, F_SEED, -1), c->value[F_SEQUENCE], c->value[F_OUT],
                         (int)cli_flag_int(c, F_THREADS, 0), style, tcb_term_progress_reporter(&tp)};
    tcb_error err = {0};
    char dir[TCB_PATH_MAX];
    int rc = tcb_frames(&o, stdout, dir, &err);
    tcb_term_progress_finish(&tp);
    if (rc) return cli_fail(&err);
    fprintf(stderr, "files: %s/\n", dir);
    return 0;
}

const cli_command cli_inspect = {
    .name = "inspect", .fn = cmd_inspect, .min_args = 3, .max_args = 3, .arg_names = "RUN_DIR METHOD PAIR",
    .accepts = BIT(F_SEED) | BIT(F_SEQUENCE) | BIT(F_OUT) | BIT(F_THREADS) | BIT(F_QUIET),
    .summary = "one evaluation pair as coloured meshes, checked against the run",
    .usage =
        "usage: tcbench inspect RUN_DIR METHOD PAIR [--seed S] [--sequence DATASET/SEQUENCE]\n"
        "                       [--out DIR] [--threads N] [--quiet]\n"
        "\n"
        "Recomputes one evaluation pair of a cell exactly as the run did (from the\n"
        "cell's fitted model), checks it against the cell file, and writes it as\n"
        "coloured meshes: source.ply and target.ply (vertices coloured by their place\n"
        "on the body), transfer.ply (each target vertex in the colour of the vertex the\n"
        "method predicted for it), error.ply (per-vertex error), recon_i/recon_j.ply\n"
        "(the method's surface samples, if it reconstructs), vertices.csv (per vertex: the\n"
        "prediction, its error and its geodesic error) and pair.json.\n"
        "\n"
        "PAIR is the pair's index in the split, or 'worst': the cell's pair with the\n"
        "largest m_sL2.\n"
        "\n"
        "options:\n"
        "  --seed S          the cell's seed (default: the run's first)\n"
        "  --sequence D/S    dataset/sequence (default: the run's only one)\n"
        "  --out DIR         where to write (default:\n"
        "                    RUN_DIR/inspect/<dataset>/<sequence>/<method>/seed_<s>/pair_<k>)\n"
        "  --threads N       threads (default: the run's; the same count reproduces the\n"
        "                    cell's numbers bit for bit)\n"
        "  --quiet           no progress output\n"
        "\n"
        "example:\n"
        "  tcbench inspect runs/atlas-cat mca worst --seed 1\n"
};

const cli_command cli_frames = {
    .name = "frames", .fn = cmd_frames, .min_args = 2, .max_args = 2, .arg_names = "RUN_DIR METHOD",
    .accepts = BIT(F_FRAMES) | BIT(F_N_FRAMES) | BIT(F_STYLE) | BIT(F_SEED) | BIT(F_SEQUENCE) | BIT(F_OUT) |
        BIT(F_THREADS) | BIT(F_QUIET),
    .summary = "a few frames of a cell as a picture: checkerboard-textured surfaces or transfers",
    .usage =
        "usage: tcbench frames RUN_DIR METHOD [--frames F,F,... | --count N] [--style auto|texture|transfer]\n"
        "                      [--seed S] [--sequence DATASET/SEQUENCE] [--out DIR] [--threads N] [--quiet]\n"
        "\n"
        "Draws a few frames of a cell from its fitted model, side by side from one\n"
        "camera in strip.png. A method that reconstructs a parametrised surface (the\n"
        "atlas family: atlasnet, dsr, mca) is drawn as its surface of each frame with\n"
        "one checkerboard in UV space, the same texture in every frame, so a patch that\n"
        "slides over the body shows it at a glance; the surfaces are also written as\n"
        "frame_<f>.obj with checker.mtl and checker.png (MeshLab and Blender open them\n"
        "as they are). A surface without charts (neupig's template moved into each\n"
        "frame) keeps each vertex in the colour of its place in the first frame drawn\n"
        "(frame_<f>.ply), so colours that slide over the body show it. Any other\n"
        "method is drawn as its transfer from the first frame:\n"
        "each frame's GT mesh with every vertex in the colour of the place on the body\n"
        "the transfer sent it to (frame_<f>.ply), so colours out of place are errors.\n"
        "A surface whose patches collapsed (a patch under 5 % of its share of the\n"
        "frame's GT area) is said so above each frame of the strip and in a warning.\n"
        "\n"
        "options:\n"
        "  --frames F,F,...  the frames (at most 16, distinct)\n"
        "  --count N         N frames evenly spaced from the first to the last (default 5)\n"
        "  --style S         texture (needs a method with a surface), transfer, or auto\n"
        "                    (default: texture when the method has one)\n"
        "  --seed S          the cell's seed (default: the run's first)\n"
        "  --sequence D/S    dataset/sequence (default: the run's only one)\n"
        "  --out DIR         where to write (default:\n"
        "                    RUN_DIR/frames/<dataset>/<sequence>/<method>/seed_<s>)\n"
        "  --threads N       threads (default: the run's)\n"
        "  --quiet           no progress output\n"
        "\n"
        "examples:\n"
        "  tcbench frames runs/atlas-cat mca --frames 0,8,16,24\n"
        "  tcbench frames runs/quick nearest --count 4\n"
};
