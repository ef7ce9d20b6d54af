/* The normalized config: what was actually run, every default spelled out,
 * saved as <run>/config.json so a results directory documents itself. */
#include <cjson/cJSON.h>
#include <string.h>

#include "tcb/config.h"
#include "tcb/metrics.h"

static cJSON *dump_evaluation(const tcb_config *c)
{
    cJSON *ev = cJSON_CreateObject();
    cJSON_AddNumberToObject(ev, "pairs", c->eval_pairs);
    cJSON_AddNumberToObject(ev, "split_seed", (double)c->split_seed);
    cJSON_AddNumberToObject(ev, "pool_size", c->pool_size);
    cJSON_AddNumberToObject(ev, "pool_seed", (double)c->pool_seed);
    cJSON_AddNumberToObject(ev, "input_points", c->input_points);
    /* Only when not the default, as the protocol below. */
    if (c->surface_samples != TCB_DEFAULT_SURFACE_SAMPLES)
        cJSON_AddNumberToObject(ev, "surface_samples", c->surface_samples);
    if (c->recon_frame != TCB_RECON_FRAME_SEQUENCE)
        cJSON_AddStringToObject(ev, "recon_frame", tcb_recon_frame_names[c->recon_frame]);
    if (c->input_normals != TCB_INPUT_NORMALS_NONE)
        cJSON_AddStringToObject(ev, "input_normals", tcb_config_input_normals_names[c->input_normals]);
    /* Only when not the default, so that the record of a run directory made
     * before the clip protocol still reads as the same settings. */
    if (c->protocols == TCB_PROTOCOL_PAIRS) return ev;
    if (c->protocols == TCB_PROTOCOL_CLIPS)
        cJSON_AddStringToObject(ev, "protocol", "clips");
    else
        cJSON_AddItemToObject(ev, "protocol", cJSON_CreateStringArray(tcb_config_protocol_names, 2));
    cJSON_AddNumberToObject(ev, "clips", c->eval_clips);
    if (c->fit_per_clip) cJSON_AddStringToObject(ev, "fit", tcb_config_fit_names[1]);
    return ev;
}

static cJSON *dump_dataset(const tcb_dataset_spec *d)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "name", d->name);
    cJSON_AddStringToObject(o, "source", tcb_config_source_names[d->source]);
    if (d->source == TCB_SOURCE_SYNTHETIC) {
        cJSON_AddNumberToObject(o, "seed", (double)d->seed);
        cJSON_AddNumberToObject(o, "frames", d->frames);
    } else {
        cJSON_AddStringToObject(o, "root", d->root);
        cJSON_AddBoolToObject(o, "optional", d->optional);
    }
    if (d->n_subjects > 0) {
        cJSON *subjects = cJSON_AddArrayToObject(o, "subjects");
        for (int k = 0; k < d->n_subjects; k++)
            cJSON_AddItemToArray(subjects, cJSON_CreateString(d->subjects[k]));
    }
    if (d->source == TCB_SOURCE_PCL_SEQ) cJSON_AddNumberToObject(o, "points", d->points);
    cJSON_AddStringToObject(o, "normalization", tcb_config_norm_names[d->norm]);
    if (d->source != TCB_SOURCE_DFAUST && d->source != TCB_SOURCE_PCL_SEQ)
        cJSON_AddBoolToObject(o, "align_rotation", d->align_rotation);
    if (d->align_rotation) cJSON_AddNumberToObject(o, "align_samples", d->align_samples);
    cJSON_AddStringToObject(o, "sampling", tcb_config_sampling_names[d->with_replacement != 0]);
    cJSON *seqs = cJSON_AddArrayToObject(o, "sequences");
    for (int k = 0; k < d->n_sequences; k++) {
        cJSON *s = cJSON_CreateObject();
        cJSON_AddStringToObject(s, "name", d->sequences[k].name);
        cJSON_AddStringToObject(s, "role", tcb_role_name(d->sequences[k].role));
        if (d->sequences[k].clip_of[0]) { /* the clip_starts of the config, one clip an entry */
            cJSON_AddStringToObject(s, "clip_of", d->sequences[k].clip_of);
            cJSON_AddNumberToObject(s, "start", d->sequences[k].start);
        }
        cJSON_AddItemToArray(seqs, s);
    }
    return o;
}

static cJSON *seed_array(const int *seeds, int n)
{
    cJSON *a = cJSON_CreateArray();
    for (int k = 0; k < n; k++) cJSON_AddItemToArray(a, cJSON_CreateNumber(seeds[k]));
    return a;
}

static cJSON *dump_method(const tcb_method_spec *m, const tcb_config *c)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "name", m->label);
    cJSON_AddStringToObject(o, "method", m->method);
    cJSON *params = cJSON_Parse(m->params_json); /* printed by cJSON: always valid */
    cJSON_AddItemToObject(o, "params", params ? params : cJSON_CreateObject());
    int own = m->n_seeds != c->n_seeds ||
              memcmp(m->seeds, c->seeds, (size_t)c->n_seeds * sizeof *c->seeds) != 0;
    if (own) cJSON_AddItemToObject(o, "seeds", seed_array(m->seeds, m->n_seeds));
    if (m->n_only_on) {
        cJSON *on = cJSON_AddArrayToObject(o, "datasets");
        for (int k = 0; k < m->n_only_on; k++) cJSON_AddItemToArray(on, cJSON_CreateString(m->only_on[k]));
    }
    if (m->plugin_digest[0]) cJSON_AddStringToObject(o, "plugin_fnv1a64", m->plugin_digest);
    return o;
}

char *tcb_config_normalized_json(const tcb_config *c)
{
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    cJSON_AddStringToObject(o, "name", c->name);
    cJSON_AddStringToObject(o, "output", c->output);
    cJSON_AddStringToObject(o, "splits_dir", c->splits_dir);
    cJSON_AddStringToObject(o, "cache_dir", c->cache_dir);
    cJSON *plugins = cJSON_AddArrayToObject(o, "plugins");
    for (int k = 0; k < c->n_plugins; k++)
        cJSON_AddItemToArray(plugins, cJSON_CreateString(c->plugins[k]));
    cJSON_AddItemToObject(o, "seeds", seed_array(c->seeds, c->n_seeds));
    cJSON_AddNumberToObject(o, "threads", c->threads);
    cJSON_AddItemToObject(o, "evaluation", dump_evaluation(c));
    cJSON *datasets = cJSON_AddArrayToObject(o, "datasets");
    for (int k = 0; k < c->n_datasets; k++)
        cJSON_AddItemToArray(datasets, dump_dataset(&c->datasets[k]));
    cJSON *methods = cJSON_AddArrayToObject(o, "methods");
    for (int k = 0; k < c->n_methods; k++) cJSON_AddItemToArray(methods, dump_method(&c->methods[k], c));
    if (c->reference[0]) {
        cJSON *ref = cJSON_AddObjectToObject(o, "reference");
        cJSON_AddStringToObject(ref, "source", c->reference);
        cJSON *tables = cJSON_AddArrayToObject(ref, "tables");
        for (int k = 0; k < c->n_reference_tables; k++)
            cJSON_AddItemToArray(tables, cJSON_CreateString(c->reference_tables[k]));
    }
    char *text = cJSON_Print(o);
    cJSON_Delete(o);
    return text;
}
