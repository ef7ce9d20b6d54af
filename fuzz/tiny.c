#include "fuzz/tiny.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/registry.h"
#include "tcb/synth.h"

static void ok(int rc, const tcb_error *err)
{
    if (rc == TCB_OK) return;
    fprintf(stderr, "fuzz setup: %s\n", err->msg);
    abort();
}

void fuzz_tiny_sequence(tcb_sequence *out)
{
    tcb_error err = {0};
    ok(tcb_synth_generate("humanoid_jacks", 1, 5, out, &err), &err);
    ok(tcb_sequence_normalize(out, TCB_NORM_FIRST_FRAME, &err), &err);
    ok(tcb_sequence_sample_pools(out, 500, 1, &err), &err);
    out->input_points = 200, out->draw_with_replacement = 0;
}

const char *fuzz_tiny_params(const char *method)
{
    if (!strcmp(method, "mca")) return "{\"preset\": \"tiny\", \"iterations\": 4, \"checkpoint_every\": 0}";
    if (!strcmp(method, "cc")) return "{\"preset\": \"tiny\", \"iterations\": 4}";
    if (!strcmp(method, "nricp")) return "{\"strategy\": \"propagate_simple\", \"rounds\": 2}";
    fprintf(stderr, "fuzz setup: no tiny params for %s\n", method);
    abort();
}

void *fuzz_tiny_method(const char *method)
{
    const tcb_method_ops *ops = tcb_registry_find(method);
    if (!ops) {
        fprintf(stderr, "fuzz setup: no method %s\n", method);
        abort();
    }
    void *self = NULL;
    tcb_error err = {0};
    ok(ops->create(fuzz_tiny_params(method), &self, &err), &err);
    return self;
}

struct nricp_method *fuzz_tiny_deform(const tcb_sequence *seq)
{
    const tcb_method_ops *ops = tcb_registry_find("nricp");
    void *self = NULL;
    tcb_error err = {0};
    ok(ops->create("{\"strategy\": \"propagate_deform\", \"rounds\": 2}", &self, &err), &err);
    tcb_fit_ctx ctx = {.seed = FUZZ_TINY_SEED, .n_threads = 1};
    ok(ops->fit(self, seq, &ctx, &err), &err);
    return self;
}

void fuzz_tiny_trainer(const tcb_sequence *seq, tcb_atlas_model **model, tcb_atlas_trainer **trainer)
{
    static const tcb_atlas_train_cfg cfg = {.loss = TCB_ATLAS_LOSS_METRIC, .M = 200, .iterations = 24,
                                            .lr = 1e-3, .alpha_mc = 0.1, .alpha_sciso = 0.001, .delta = 1,
                                            .divergence = 1e4};
    tcb_error err = {0};
    ok(tcb_atlas_model_create(32, 4, model, &err), &err);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, FUZZ_TINY_SEED, "atlas/init");
    tcb_atlas_model_init(*model, &rng);
    ok(tcb_atlas_trainer_create(&cfg, *model, seq, FUZZ_TINY_SEED, trainer, &err), &err);
}
