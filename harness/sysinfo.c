/* Facts about the running tcbench recorded in every cell: the source
 * revision (so a result can be traced to code) and the peak memory. */
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>

#include "harness/internal.h"

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
