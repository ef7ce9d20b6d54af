/* `tcbench frames`: a few frames of a fitted cell as a picture (tcb/frames.h).
 *
 * A command of its own rather than an `inspect` mode: inspect is about one
 * evaluation pair checked against the cell file, this is about a strip of
 * frames outside any pair, with its own files and default directory. The
 * cell is picked and reopened by the pieces inspect uses (cell_target.c). */
#include "tcb/frames.h"

#include <math.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "views/cell_target.h"
#include "views/frames_style.h"

void tcb_frames_rng(const tcb_cell_job *cell, int i, int j, tcb_rng *rng)
{
    char label[TCB_PATH_MAX];
    if (j < 0) snprintf(label, sizeof label, "frames/%s/%s/%d", cell->dataset->name, cell->seq->name, i);
    else snprintf(label, sizeof label, "frames/%s/%s/%d/%d", cell->dataset->name, cell->seq->name, i, j);
    tcb_rng_seed_stream(rng, (uint64_t)cell->seed, label);
}

static int named_frames(const tcb_frames_opts *o, const tcb_sequence *seq, int *frames, int *n, tcb_error *err)
{
    if (o->n_frames < 1 || o->n_frames > TCB_FRAMES_MAX)
        return tcb_fail(err, TCB_ERR_INPUT, "--frames: %d frames (1 to %d)", o->n_frames, TCB_FRAMES_MAX);
    for (int k = 0; k < o->n_frames; k++) {
        int f = o->frames[k];
        if (f < 0 || f >= seq->n_frames)
            return tcb_fail(err, TCB_ERR_INPUT, "--frames: frame %d is outside %s (frames 0 to %d)", f, seq->name,
                            seq->n_frames - 1);
        for (int m = 0; m < k; m++)
            if (frames[m] == f) return tcb_fail(err, TCB_ERR_INPUT, "--frames: frame %d is named twice", f);
        frames[k] = f;
    }
    *n = o->n_frames;
    return TCB_OK;
}

/* `count` frames from the first to the last, as evenly as whole frames go. */
static int spaced_frames(const tcb_frames_opts *o, const tcb_sequence *seq, int *frames, int *n, tcb_error *err)
{
    int F = seq->n_frames;
    int c = o->count > 0 ? o->count : (F < TCB_FRAMES_DEFAULT ? F : TCB_FRAMES_DEFAULT);
    if (c > F || c > TCB_FRAMES_MAX)
        return tcb_fail(err, TCB_ERR_INPUT, "--count %d: %s has %d frames and a strip at most %d", c, seq->name, F,
                        TCB_FRAMES_MAX);
    for (int k = 0; k < c; k++) frames[k] = c == 1 ? 0 : (int)lround((double)k * (F - 1) / (c - 1));
    *n = c;
    return TCB_OK;
}

static int texture_wanted(const tcb_frames_opts *o, const tcb_cell_target *t, int *texture, tcb_error *err)
{
    *texture = o->style == TCB_FRAMES_TEXTURE || (o->style == TCB_FRAMES_AUTO && tcb_method_has_surface(t->ops));
    if (*texture && !tcb_method_has_surface(t->ops))
        return tcb_fail(err, TCB_ERR_INPUT,
                        "--style texture: method '%s' (%s) has no textured surface (no `surface` in its table); "
                        "--style transfer draws its correspondences",
                        t->m->label, t->ops->name);
    return TCB_OK;
}

static void print_account(FILE *out, const tcb_cell_target *t, const int *frames, int n, int texture)
{
    if (!out) return;
    fprintf(out, "%s/%s %s seed %d, %s, frames", t->d->name, t->s->name, t->m->label, t->seed,
            texture ? "textured surface" : "transfer");
    for (int k = 0; k < n; k++) fprintf(out, "%s %d", k ? "," : "", frames[k]);
    fputc('\n', out);
    if (texture)
        fprintf(out, "  look for: a check pattern that slides over the body, flips or stretches from frame to "
                     "frame (one texture, the same (u, v) in every frame; a surface without charts: each vertex "
                     "in the colour of its place in frame %d)\n",
                frames[0]);
    else
        fprintf(out, "  look for: colours out of place in frames %s %d (each vertex in the colour of where "
                     "the transfer from frame %d sent it)\n",
                n > 1 ? "after" : "beside", frames[0], frames[0]);
}

int tcb_frames(const tcb_frames_opts *o, FILE *out, char *out_path, tcb_error *err)
{
    tcb_config cfg;
    int rc = tcb_run_config_open(o->run_dir, &cfg, err);
    if (rc) return rc;
    tcb_cell_target t;
    tcb_cell_session ses = {0};
    int frames[TCB_FRAMES_MAX], n = 0, texture = 0;
    char dir[TCB_PATH_MAX];
    rc = tcb_cell_target_resolve(&cfg, o->method, o->seed, o->sequence, &t, err);
    if (!rc) rc = texture_wanted(o, &t, &texture, err);
    if (!rc) rc = tcb_cell_session_open(&cfg, o->run_dir, &t, o->threads, o->reporter, &ses, err);
    if (!rc) rc = o->frames ? named_frames(o, &ses.seq, frames, &n, err) : spaced_frames(o, &ses.seq, frames, &n, err);
    if (!rc && o->out_dir) rc = tcb_path_join(dir, sizeof dir, err, "%s", o->out_dir);
    else if (!rc)
        rc = tcb_path_join(dir, sizeof dir, err, "%s/frames/%s/%s/%s/seed_%d", o->run_dir, t.d->name, t.s->name,
                           t.m->label, t.seed);
    tcb_frames_job f = {&ses.job, frames, n, dir};
    if (!rc) rc = texture ? tcb_frames_texture(&f, err) : tcb_frames_transfer(&f, err);
    if (!rc) print_account(out, &t, frames, n, texture);
    if (!rc && out_path) snprintf(out_path, TCB_PATH_MAX, "%s", dir);
    tcb_cell_session_close(&ses);
    tcb_config_free(&cfg);
    return rc;
}
