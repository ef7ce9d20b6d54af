/* The cells of a run directory that Slurm still has queued, for `tcbench
 * status`: squeue lists the user's array tasks, one line each, and a task
 * whose job comment names the run directory (scripts/slurm/submit.sh sets
 * "tcbench run=DIR", or "tcbench shards=N run=DIR" with --tasks N) marks
 * the cells it will run as the scripts map them: its index is the cell id,
 * or with N shards every id that is its index modulo N. Only pending and
 * running tasks count (squeue also lists finished ones for a while).
 * Only a run directory that submit.sh has submitted (it leaves
 * TCB_SLURM_MARK there) is asked about: a local run's status stays quiet
 * and quick wherever squeue is installed. */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "harness/harness_internal.h"

#define SQUEUE_CMD "squeue --me --noheader --array --format='%F|%K|%T|%k' 2>&1"

/* The states of a task that will still run (or is running) its cells. */
static int state_queued(const char *state)
{
    static const char *const live[] = {"PENDING",      "CONFIGURING", "RUNNING",  "SUSPENDED", "REQUEUED",
                                       "REQUEUE_HOLD", "REQUEUE_FED", "RESIZING", NULL};
    for (int k = 0; live[k]; k++)
        if (!strcmp(state, live[k])) return 1;
    return 0;
}

/* The shard count a comment names for run_dir: 0 (one cell per task), N,
 * or -1 when the comment is not of this run directory. */
static int comment_shards(const char *comment, const char *run_dir)
{
    const char *p = comment;
    int shards = 0, used = 0;
    if (strncmp(p, "tcbench ", 8)) return -1;
    p += 8;
    if (sscanf(p, "shards=%d %n", &shards, &used) == 1 && used > 0) {
        if (shards <= 0) return -1;
        p += used;
    }
    if (strncmp(p, "run=", 4) || strcmp(p + 4, run_dir)) return -1;
    return shards;
}

static void add_job(tcb_slurm_queue *q, const char *job)
{
    size_t used = strlen(q->jobs), n = strlen(job);
    const char *last = strrchr(q->jobs, ' ');
    if (!strcmp(last ? last + 1 : q->jobs, job)) return; /* squeue lists a job's tasks together */
    if (used + n + 2 < sizeof q->jobs) snprintf(q->jobs + used, sizeof q->jobs - used, "%s%s", used ? " " : "", job);
}

/* One line of squeue: "ARRAY_JOB|TASK|STATE|COMMENT". */
static void queue_line(tcb_slurm_queue *q, char *line, const char *run_dir)
{
    line[strcspn(line, "\n")] = '\0';
    char *job = line, *task = strchr(job, '|'), *state = task ? strchr(task + 1, '|') : NULL;
    char *comment = state ? strchr(state + 1, '|') : NULL;
    if (!comment) return;
    *task++ = *state++ = *comment++ = '\0';
    char *end;
    long index = strtol(task, &end, 10);
    int shards = comment_shards(comment, run_dir);
    if (end == task || *end || index < 0 || shards < 0 || !state_queued(state)) return;
    if (shards && index >= shards) return;
    long step = shards ? shards : q->n_cells; /* one cell per task: a single id */
    int hit = 0;
    for (long id = index; id < q->n_cells; id += step) {
        hit += !q->queued[id];
        q->queued[id] = 1;
    }
    if (hit) add_job(q, job);
}

int tcb_slurm_queue_read(const char *run_dir, int n_cells, tcb_slurm_queue *q, char *note, size_t note_size)
{
    memset(q, 0, sizeof *q);
    note[0] = '\0';
    char abs_dir[PATH_MAX];
    char mark[PATH_MAX + 32];
    if (!realpath(run_dir, abs_dir)) return 0; /* no directory: nothing was submitted for it */
    snprintf(mark, sizeof mark, "%s/%s", abs_dir, TCB_SLURM_MARK);
    if (access(mark, F_OK)) return 0; /* never submitted to Slurm: nothing to ask */
    if (!(q->queued = calloc(n_cells > 0 ? n_cells : 1, 1))) return -1;
    q->n_cells = n_cells;
    FILE *p = popen(SQUEUE_CMD, "r");
    if (!p) return 0;
    char line[8192], last[512] = "";
    while (fgets(line, sizeof line, p)) {
        snprintf(last, sizeof last, "%.*s", (int)strcspn(line, "\n"), line);
        queue_line(q, line, abs_dir);
    }
    int status = pclose(p);
    int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    if (code == 0) {
        q->asked = 1;
        return 0;
    }
    memset(q->queued, 0, n_cells > 0 ? n_cells : 1);
    q->jobs[0] = '\0';
    if (code != 127) /* 127: no squeue here, nothing to say */
        snprintf(note, note_size, "squeue failed (%s), so cells queued in Slurm count as missing",
                 last[0] ? last : "no message");
    return 0;
}

void tcb_slurm_queue_free(tcb_slurm_queue *q)
{
    free(q->queued);
    q->queued = NULL;
}
