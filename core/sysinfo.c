/* Facts about the running tcbench recorded in every cell: the source
 * revision (so a result can be traced to code) and the peak memory; and
 * the machine a calibration names. */
#include "tcb/sysinfo.h"

#include <cblas.h>
#include <cjson/cJSON.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/utsname.h>
#include <time.h>

#include "tcb/version.h"

void tcb_git_revision(char *out, size_t size)
{
    snprintf(out, size, "unknown");
#ifdef TCB_SOURCE_DIR
    /* Asked at run time, not baked in at build time, so a rebuild is not
     * needed for the revision to be right; a missing git or a tree without
     * commits leaves "unknown". */
    FILE *p = popen("git -C '" TCB_SOURCE_DIR "' rev-parse --short HEAD 2>/dev/null", "r");
    if (!p) return;
    char line[64];
    int ok = fgets(line, sizeof line, p) != NULL;
    int status = pclose(p);
    if (!ok || status != 0) return;
    line[strcspn(line, "\r\n")] = '\0';
    if (line[0]) snprintf(out, size, "%s", line);
#endif
}

long tcb_peak_rss_kb(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0) return 0;
    return ru.ru_maxrss; /* Linux reports KiB */
}

/* The value of /proc/cpuinfo's first "model name" line; "unknown CPU". */
static void cpu_model(char *out, size_t size)
{
    snprintf(out, size, "unknown CPU");
    FILE *f = fopen("/proc/cpuinfo", "r");
    char line[512];
    while (f && fgets(line, sizeof line, f)) {
        char *colon = strchr(line, ':');
        if (strncmp(line, "model name", 10) || !colon) continue;
        colon += 1 + (colon[1] == ' ');
        colon[strcspn(colon, "\r\n")] = '\0';
        snprintf(out, size, "%s", colon);
        break;
    }
    if (f) fclose(f);
}

char *tcb_machine_describe(char *summary, size_t size)
{
    char cpu[256], rev[64], date[32];
    struct utsname u;
    double load[3] = {0};
    time_t now = time(NULL);
    cpu_model(cpu, sizeof cpu);
    tcb_git_revision(rev, sizeof rev);
    strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", gmtime(&now));
    int cores = tcb_cpu_count();
    getloadavg(load, 3);
    /* the load says how far the costs are from an idle machine's */
    snprintf(summary, size, "%s, %d core%s, load %.1f", cpu, cores, cores == 1 ? "" : "s", load[0]);
    cJSON *m = cJSON_CreateObject();
    if (!m) return NULL;
    cJSON_AddStringToObject(m, "summary", summary);
    cJSON_AddStringToObject(m, "cpu", cpu);
    cJSON_AddNumberToObject(m, "cores", cores);
    cJSON_AddStringToObject(m, "kernel", uname(&u) ? "unknown" : u.release);
    cJSON_AddStringToObject(m, "compiler", __VERSION__);
    cJSON_AddStringToObject(m, "openblas", openblas_get_config());
    cJSON_AddNumberToObject(m, "openmp", _OPENMP);
    /* spinning threads of a busy machine's cells slow each other down */
    const char *policy = getenv("OMP_WAIT_POLICY");
    cJSON_AddStringToObject(m, "omp_wait_policy", policy ? policy : "(unset)");
    cJSON_AddStringToObject(m, "cjson", cJSON_Version());
    cJSON_AddStringToObject(m, "tcbench", TCB_VERSION);
    cJSON_AddStringToObject(m, "revision", rev);
    cJSON_AddStringToObject(m, "date", date);
    cJSON_AddNumberToObject(m, "load_average", load[0]); /* other work competing for the cores at the start */
    char *text = cJSON_PrintUnformatted(m);
    cJSON_Delete(m);
    return text;
}

int tcb_cpu_count(void) { return omp_get_num_procs(); }
