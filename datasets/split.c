/* Evaluation splits: the fixed list of (i, j) pairs every method of a
 * sequence is scored on (reference-protocol §5.2), drawn once from a seeded
 * stream and kept in a file so later runs and other methods reuse them. */
#include "tcb/split.h"

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"

static const char *const role_names[] = {"train", "validation", "test", NULL};

const char *tcb_role_name(tcb_role role)
{
    return role >= TCB_ROLE_TRAIN && role <= TCB_ROLE_TEST ? role_names[role] : "unknown";
}

int tcb_role_parse(const char *name, tcb_role *out)
{
    for (int r = 0; role_names[r]; r++)
        if (name && strcmp(name, role_names[r]) == 0) {
            *out = (tcb_role)r;
            return 0;
        }
    return -1;
}

int tcb_split_make(const char *dataset, const char *sequence, tcb_role role, int n_frames,
                   int n_pairs, uint64_t seed, tcb_split *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    if (strlen(dataset) >= sizeof out->dataset || strlen(sequence) >= sizeof out->sequence)
        return tcb_fail(err, TCB_ERR_INPUT, "split %s/%s: name too long", dataset, sequence);
    if (n_frames < 2)
        return tcb_fail(err, TCB_ERR_INPUT, "split %s/%s: needs at least 2 frames, got %d",
                        dataset, sequence, n_frames);
    if (n_pairs < 0)
        return tcb_fail(err, TCB_ERR_INPUT, "split %s/%s: negative pair count %d", dataset,
                        sequence, n_pairs);
    out->pairs = malloc((size_t)(n_pairs > 0 ? n_pairs : 1) * 2 * sizeof(int32_t));
    if (!out->pairs) return tcb_fail(err, TCB_ERR_NOMEM, "split: out of memory");
    snprintf(out->dataset, sizeof out->dataset, "%s", dataset);
    snprintf(out->sequence, sizeof out->sequence, "%s", sequence);
    out->role = role, out->n_frames = n_frames, out->seed = seed, out->n_pairs = n_pairs;

    char label[256];
    snprintf(label, sizeof label, "split/%s/%s", dataset, sequence);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, seed, label);
    for (int p = 0; p < n_pairs; p++) {
        int i = (int)tcb_rng_below(&rng, (uint32_t)n_frames);
        out->pairs[2 * p] = i;
        out->pairs[2 * p + 1] = tcb_pair_sample(TCB_PAIRS_WITHIN_SEQ, 0, n_frames, i, &rng);
    }
    return TCB_OK;
}

void tcb_split_free(tcb_split *s)
{
    free(s->pairs);
    s->pairs = NULL;
    s->n_pairs = 0;
}

/* The first field where `s` disagrees with the request, written into what
 * (field name) and have/want (values); 0 when everything agrees. */
static int disagreement(const tcb_split *s, const tcb_split *want, const char **what,
                        char *have, char *wanted, size_t size)
{
    if (strcmp(s->dataset, want->dataset) != 0) {
        *what = "dataset";
        snprintf(have, size, "\"%s\"", s->dataset), snprintf(wanted, size, "\"%s\"", want->dataset);
    } else if (strcmp(s->sequence, want->sequence) != 0) {
        *what = "sequence";
        snprintf(have, size, "\"%s\"", s->sequence);
        snprintf(wanted, size, "\"%s\"", want->sequence);
    } else if (s->role != want->role) {
        *what = "role";
        snprintf(have, size, "%s", tcb_role_name(s->role));
        snprintf(wanted, size, "%s", tcb_role_name(want->role));
    } else if (s->n_frames != want->n_frames) {
        *what = "n_frames";
        snprintf(have, size, "%d", s->n_frames), snprintf(wanted, size, "%d", want->n_frames);
    } else if (s->n_pairs != want->n_pairs) {
        *what = "n_pairs";
        snprintf(have, size, "%d", s->n_pairs), snprintf(wanted, size, "%d", want->n_pairs);
    } else if (s->seed != want->seed) {
        *what = "seed";
        snprintf(have, size, "%" PRIu64, s->seed), snprintf(wanted, size, "%" PRIu64, want->seed);
    } else {
        return 0;
    }
    return 1;
}

int tcb_split_obtain(const char *path, const char *dataset, const char *sequence,
                     tcb_role role, int n_frames, int n_pairs, uint64_t seed,
                     tcb_split *out, tcb_error *err)
{
    /* Making first also validates the request before any file is touched. */
    int rc = tcb_split_make(dataset, sequence, role, n_frames, n_pairs, seed, out, err);
    if (rc) return rc;
    if (!tcb_is_file(path)) {
        rc = tcb_split_save(path, out, err);
        if (rc) tcb_split_free(out);
        return rc;
    }
    tcb_split want = *out;
    want.pairs = NULL;
    tcb_split_free(out);
    rc = tcb_split_load(path, out, err);
    if (rc) return rc;
    const char *what;
    char have[160], wanted[160];
    if (disagreement(out, &want, &what, have, wanted, sizeof have)) {
        tcb_split_free(out);
        return tcb_fail(err, TCB_ERR_INPUT,
                        "%s: %s is %s in the split file but %s is requested "
                        "(delete the file to draw a new split)",
                        path, what, have, wanted);
    }
    return TCB_OK;
}
