/* tcbench — facts about this process and machine (core/sysinfo.c): the
 * source revision, peak memory, the machine a calibration describes, the
 * cores OpenMP may use. */
#ifndef TCB_SYSINFO_H
#define TCB_SYSINFO_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Short git revision of the source tree tcbench was built from, or
 * "unknown". (core/sysinfo.c) */
void tcb_git_revision(char *out, size_t size);
/* Peak resident set size of this process so far, in KiB. */
long tcb_peak_rss_kb(void);
/* The machine a calibration is made on, as JSON text (malloc'ed; NULL out
 * of memory): CPU model, cores, kernel, compiler, library versions,
 * tcbench's revision, the date and the load average; summary gets "CPU
 * model, N cores, load L" (the load average at the start). */
char *tcb_machine_describe(char *summary, size_t size);
/* The cores OpenMP may use. */
int tcb_cpu_count(void);

#ifdef __cplusplus
}
#endif
#endif
