/* PDG's optimisation (github vc-bonn/preconditioned-deformation-grids
 * @ cf21c7d: src/optimization.py, configs/method/fit.json; the template's
 * parametrisation src/geometry/): every step is one epoch over all frames
 * and transitions (full batch). The fields' parameters U take Adam at
 * lr_grid·lr_growth^l for level l; the template's vertices v are
 * parametrised by Large Steps, u = (I + λL)v (tcb/large_steps.h, λ = 16),
 * and u takes Adam at lr_template, pulled only by the robust Chamfer
 * between v and the keyframe's points; the chains start from v as it is at
 * the epoch's start, held constant (methods/pdg/objective.h). The Adams all
 * step every epoch, so one Adam with a group per level and one for the
 * template is theirs. The state is checkpointed through
 * neural/train_ckpt.h and continued bit-identically; a non-finite gradient
 * or a loss beyond divergence × the first epoch's ends the training. */
#ifndef TCB_PDG_TRAIN_H
#define TCB_PDG_TRAIN_H

#include "methods/pdg/objective.h"
#include "neural/adam.h"
#include "tcb/large_steps.h"
#include "tcb/mesh.h"

typedef struct tcb_pdg_arch {
    int levels;                 /* 10 */
    tcb_pdg_rotation rotation;  /* released (methods/pdg/field.h) */
    double lambda, lambda_growth; /* the fields' λ_l = 0.25·1.5^l */
    double template_lambda;     /* 16 */
    double edge_weight, alpha;  /* 250, 0.3 */
} tcb_pdg_arch;

/* The reference's (fit.json). */
tcb_pdg_arch tcb_pdg_arch_reference(void);

typedef struct tcb_pdg_schedule {
    long long epochs, warmup;   /* 5 000, 101 */
    double lr_grid, lr_growth;  /* 0.005, 1.1 */
    double lr_template;         /* 1e-4 */
    double divergence;          /* 0: no test */
} tcb_pdg_schedule;

/* What the training reads, the caller's for the trainer's life: n frames'
 * clouds in the cube and their indexes, the keyframe, the template as it
 * starts (its faces stay). */
typedef struct tcb_pdg_data {
    int n, key;
    const float *const *points;
    const int *n_points;
    const tcb_nn *const *points_index;
    const tcb_mesh *template_mesh;
} tcb_pdg_data;

typedef struct tcb_pdg_trainer {
    tcb_pdg_arch arch;
    tcb_pdg_schedule sched;
    const tcb_pdg_data *data;
    tcb_pdg_fields fields;
    tcb_large_steps template_ls;
    size_t n_params;            /* fields.off[levels] + 3·nv: U, then u */
    float *params, *grads;      /* [n_params] */
    float *values;              /* V [fields.off[levels]] */
    float *verts;               /* v [nv][3], of u */
    float *edge_len;            /* [template_ls.ne] ℓ_e(v) */
    double *scratch;
    tcb_adam adam;
    size_t bounds[TCB_PDG_MAX_LEVELS + 2];
    double lrs[TCB_PDG_MAX_LEVELS + 1];
    long long it;               /* epochs done */
    double loss0;
    tcb_pdg_loss last;          /* the last epoch's objective */
    double template_loss;       /* and its template Chamfer */
} tcb_pdg_trainer;

/* The fields at zero, u = (I + λL) v of the template. */
int tcb_pdg_trainer_init(tcb_pdg_trainer *t, const tcb_pdg_arch *a, const tcb_pdg_schedule *s, const tcb_pdg_data *d,
                         tcb_error *err);
void tcb_pdg_trainer_free(tcb_pdg_trainer *t);

/* One epoch: the template's v and the fields' V from the parameters, the
 * objective and the template's Chamfer with their gradients, then Adam. */
int tcb_pdg_train_step(tcb_pdg_trainer *t, double *loss, tcb_error *err);

/* X [n][nv][3]: the template of the current parameters carried into every
 * frame (the fitted meshes). */
int tcb_pdg_trainer_frames(tcb_pdg_trainer *t, float *X, tcb_error *err);

/* The whole training state; a checkpoint of other settings (the rotation
 * among them) is refused. */
int tcb_pdg_train_save(const tcb_pdg_trainer *t, uint64_t seed, double seconds, const char *path, tcb_error *err);
int tcb_pdg_train_load(tcb_pdg_trainer *t, uint64_t seed, const char *path, double *seconds, tcb_error *err);

#endif
