/* `tcbench score`: predictions computed anywhere scored as a cell of a
 * run. */
#include <stdio.h>

#include "cli/cli.h"
#include "tcb/score.h"

static int cmd_score(const cli_args *c)
{
    static const struct { int flag; const char *text; } required[] = {
        {F_DATASET, "--dataset D"}, {F_SEQUENCE, "--sequence S"}, {F_PRED, "--pred DIR|FILE.npz"}, {F_NAME, "--name LABEL"}};
    for (size_t k = 0; k < sizeof required / sizeof required[0]; k++)
        if (!c->value[required[k].flag]) return cli_usage_error("score", "%s is required", required[k].text);
    long long seed = cli_flag_int(c, F_SEED, 0);
    tcb_config cfg;
    int rc = cli_load_config(c, &cfg);
    if (rc) return rc;
    tcb_score_opts o = {c->value[F_DATASET], c->value[F_SEQUENCE], c->value[F_PRED], c->value[F_NAME], (int)seed,
                        c->value[F_OUT], c->set[F_FORCE], c->set[F_ANY_FRAME]};
    tcb_error err = {0};
    char path[TCB_PATH_MAX];
    tcb_summary s;
    rc = tcb_score(&cfg, &o, path, &s, &err);
    tcb_config_free(&cfg);
    if (rc) return cli_fail(&err);
    printf("%s/%s %s: %d pairs, m_sL2 %.2f  rank %.2f  AUC %.2f  CD -\n", o.dataset, o.sequence, o.label,
           s.n_pairs, 1e3 * s.sl2.mean, 1e2 * s.rank.mean, 1e2 * s.auc.mean);
    fprintf(stderr, "cell: %s\n", path);
    return 0;
}

const cli_command cli_score = {
    .name = "score", .fn = cmd_score, .min_args = 1, .max_args = 1, .arg_names = "CONFIG",
    .accepts = BIT(F_DATASET) | BIT(F_SEQUENCE) | BIT(F_PRED) | BIT(F_NAME) | BIT(F_SEED) | BIT(F_OUT) |
        BIT(F_FORCE) | BIT(F_ROOT) | BIT(F_VARIANT) | BIT(F_THREADS) | BIT(F_ANY_FRAME),
    .summary = "score correspondences computed elsewhere (.npy files) as a cell of a run",
    .usage =
        "usage: tcbench score CONFIG --dataset D --sequence S --pred DIR|FILE.npz --name LABEL\n"
        "                    [--seed S] [--out DIR] [--force] [--any-frame] [--root DATASET=DIR]...\n"
        "                    [--variant NAME] [--threads N]\n"
        "\n"
        "Scores correspondences computed anywhere as a cell of the config's run. The\n"
        "predictions hold one NumPy array per evaluation pair of the sequence's common\n"
        "split, named by the pair's index (pair k is the split file's pairs[k] = [i, j]):\n"
        "a directory of .npy files 0.npy, 1.npy, ..., or one .npz whose members are\n"
        "those files (np.savez(FILE, **{str(k): a_k}); stored or deflated). For each of\n"
        "the K vertices of frame i, the array holds either the predicted vertex id of\n"
        "frame j (integers, shape (K,)) or the predicted point on frame j (float32 or\n"
        "float64, shape (K, 3), in the split's normalised frame, projected onto frame\n"
        "j's vertices as a method's transfer is). The pairs are scored by the code that\n"
        "scores a method's cells, and the cell goes to RUN/cells/D/S/LABEL/seed_<S>.json,\n"
        "so 'report' and 'check' show it as a row (CD '-': no reconstructions). A\n"
        "missing or surplus file or member, a wrong shape or dtype, an id out of range,\n"
        "a NaN, points mostly farther than half a box diagonal from frame j's bounding\n"
        "box (another frame: the error says the split's normalisation) are errors\n"
        "naming the file, and nothing is written. docs/formats.md describes the files,\n"
        "with a numpy example.\n"
        "\n"
        "options:\n"
        "  --dataset D     a dataset of the config\n"
        "  --sequence S    one of its sequences\n"
        "  --pred P        the predictions: a directory of <k>.npy, or an .npz\n"
        "  --name LABEL    the row's name; not a label of one of the config's methods\n"
        "  --seed S        the cell's seed (default 0): several prediction sets of one\n"
        "                  method are several seeds of one row\n"
        "  --out DIR       run directory (default: the config's \"output\")\n"
        "  --force         replace the cell when it exists\n"
        "  --any-frame     score points however far they lie from the target frame\n"
        "  --root D=DIR    the data of dataset D, as for run\n"
        "  --variant NAME  the config's variant, as for run\n"
        "  --threads N     threads for the projection and the metrics\n"
        "\n"
        "examples:\n"
        "  tcbench score configs/quick.json --dataset synth --sequence quadruped_trot \\\n"
        "      --pred results.npz --name my_method\n"
        "  tcbench score configs/quick.json --dataset synth --sequence quadruped_walk \\\n"
        "      --pred predictions/ --name my_method\n"
};
