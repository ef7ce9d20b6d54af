/* The training presets a run's rows ran, said above its tables (issue 30).
 *
 * Only preset `paper` is the paper's training; the `cpu` presets train a
 * fraction as long, and a table at `cpu` read as the paper's could tell the
 * opposite of the paper where the margins need the full training. So every
 * report whose cells name a preset other than `paper` says so first. The
 * presets are read from the cells' params as the config gave them (a row's
 * first cell: the seeds of a row share params); a trained method run
 * without a "preset" key runs its default, which docs/protocol.md names. */
#include <string.h>

#include "reports/writers.h"
#include "tcb/json.h"

/* The "preset" of a row's compact params, copied to out ("" when none). */
static void row_preset(const tcb_rpt_row *row, char *out, size_t size)
{
    out[0] = '\0';
    if (!row->params[0]) return;
    cJSON *p = cJSON_Parse(row->params);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(p, "preset");
    if (cJSON_IsString(v)) snprintf(out, size, "%s", v->valuestring);
    cJSON_Delete(p);
}

/* "method `preset`" unless the list already has it (each separated by ", "). */
static void add_entry(char list[TCB_RPT_PRESETS_MAX], const char *method, const char *preset)
{
    char entry[160], bounded[168];
    snprintf(entry, sizeof entry, "%s `%s`", method, preset);
    snprintf(bounded, sizeof bounded, ", %s, ", entry);
    char padded[TCB_RPT_PRESETS_MAX + 4];
    snprintf(padded, sizeof padded, ", %s, ", list);
    if (strstr(padded, bounded)) return;
    size_t used = strlen(list);
    snprintf(list + used, TCB_RPT_PRESETS_MAX - used, "%s%s", used ? ", " : "", entry);
}

int tcb_rpt_presets(const tcb_rpt *r, char list[TCB_RPT_PRESETS_MAX])
{
    int not_paper = 0;
    list[0] = '\0';
    for (int k = 0; k < r->n_blocks; k++)
        for (int i = 0; i < r->blocks[k].n_rows; i++) {
            const tcb_rpt_row *row = &r->blocks[k].rows[i];
            char preset[64];
            row_preset(row, preset, sizeof preset);
            if (!preset[0]) continue;
            not_paper |= strcmp(preset, "paper") != 0;
            add_entry(list, row->method, preset);
        }
    return not_paper;
}

void tcb_rpt_write_presets_md(FILE *f, const tcb_rpt *r)
{
    char list[TCB_RPT_PRESETS_MAX];
    int not_paper = tcb_rpt_presets(r, list);
    if (!list[0]) return;
    if (!not_paper) {
        fprintf(f, "**Presets**: %s: the paper's training.\n\n", list);
        return;
    }
    fprintf(f, "**Presets**: %s. These are not the paper's training (only preset `paper` is: its "
               "iterations and network sizes): the numbers below are not the paper's, and an ordering "
               "that needs the full training may differ from the paper's (docs/protocol.md, "
               "\"Presets\").\n\n", list);
}
