/* tcb/tetmesh.h: Debian's tetgen program on files. TetGen is a program and a
 * C++ library, but Debian ships only the program (no libtetgen), so tcbench
 * writes the shell as a .smesh file, runs `tetgen` on it, and reads the
 * .node and .ele files it writes, in a directory of its own. */
#include "tcb/tetmesh.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "meshing/meshing_internal.h"
#include "tcb/fsutil.h"

extern char **environ;

void tcb_tetmesh_free(tcb_tetmesh *t)
{
    free(t->verts);
    free(t->tets);
    memset(t, 0, sizeof *t);
}

static int check_shell(const tcb_mesh *m, tcb_error *err)
{
    int rc = tcb_meshing_check_mesh(m, err);
    if (!rc && (m->n_verts < 4 || m->n_faces < 4))
        rc = tcb_fail(err, TCB_ERR_INPUT, "tetgen: a shell of %d vertices and %d faces encloses nothing", m->n_verts,
                      m->n_faces);
    return rc;
}

/* The shell as TetGen's .smesh: nodes, then the facets, no holes or
 * regions. %.9g gives back every float exactly. */
static int write_smesh(const char *path, const tcb_mesh *m, tcb_error *err)
{
    FILE *f = fopen(path, "w");
    if (!f) return tcb_fail(err, TCB_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    fprintf(f, "%d 3 0 0\n", m->n_verts);
    for (int i = 0; i < m->n_verts; i++)
        fprintf(f, "%d %.9g %.9g %.9g\n", i, m->verts[3 * i], m->verts[3 * i + 1], m->verts[3 * i + 2]);
    fprintf(f, "%d 0\n", m->n_faces);
    for (int i = 0; i < m->n_faces; i++)
        fprintf(f, "3 %d %d %d\n", m->faces[3 * i], m->faces[3 * i + 1], m->faces[3 * i + 2]);
    fprintf(f, "0\n0\n");
    if (ferror(f) | fclose(f)) return tcb_fail(err, TCB_ERR_IO, "%s: write failed", path);
    return TCB_OK;
}

/* The last non-empty line of the program's output, for an error message. */
static void last_line(const char *log, char *out, size_t size)
{
    char *text = NULL;
    size_t len = 0;
    tcb_error ignored = {0};
    snprintf(out, size, "no output");
    if (tcb_read_file(log, &text, &len, &ignored)) return;
    while (len > 0 && (text[len - 1] == '\n' || text[len - 1] == ' ')) text[--len] = '\0';
    const char *start = len ? strrchr(text, '\n') : NULL;
    if (len) snprintf(out, size, "%.200s", start ? start + 1 : text);
    free(text);
}

/* Runs tetgen with `switches` on input, its output and errors into log. */
static int run_tetgen(const char *switches, const char *input, const char *log, tcb_error *err)
{
    posix_spawn_file_actions_t fa;
    if (posix_spawn_file_actions_init(&fa)) return tcb_fail(err, TCB_ERR_NOMEM, "tetgen: cannot prepare a process");
    posix_spawn_file_actions_addopen(&fa, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
    char *argv[] = {TCB_TETGEN_PROGRAM, (char *)switches, (char *)input, NULL};
    pid_t pid;
    int e = posix_spawnp(&pid, TCB_TETGEN_PROGRAM, &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    if (e == ENOENT)
        return tcb_fail(err, TCB_ERR_UNSUPPORTED,
                        "tetgen: the program %s is not on PATH (Debian's tetgen package; scripts/setup.sh installs it)",
                        TCB_TETGEN_PROGRAM);
    if (e) return tcb_fail(err, TCB_ERR_IO, "tetgen: cannot start %s: %s", TCB_TETGEN_PROGRAM, strerror(e));
    int status;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) return tcb_fail(err, TCB_ERR_INTERNAL, "tetgen: waitpid: %s", strerror(errno));
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return TCB_OK;
    char line[256];
    last_line(log, line, sizeof line);
    if (WIFEXITED(status))
        return tcb_fail(err, TCB_ERR_NUMERIC, "tetgen %s failed (exit status %d): %s", switches,
                        WEXITSTATUS(status), line);
    /* TetGen ends on a bad input by throwing (which aborts the program) or
     * crashing, mostly without a word of why. */
    return tcb_fail(err, TCB_ERR_NUMERIC,
                    "tetgen %s failed (signal %d; an open or self-intersecting shell stops it so): %s", switches,
                    WTERMSIG(status), line);
}

/* Reads one of TetGen's tables: a header line "<rows> <cols> ..." and rows
 * "<index> <cols values>"; the values go to out as doubles (malloc'ed). */
static int read_table(const char *path, int cols, int *rows, double **out, tcb_error *err)
{
    *out = NULL;
    FILE *f = fopen(path, "r");
    if (!f) return tcb_fail(err, TCB_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
    char buf[512];
    int line = 0, n = -1, c = -1, rc = TCB_OK;
    while (n < 0 && fgets(buf, sizeof buf, f)) {
        line++;
        if (buf[strspn(buf, " \t")] == '#' || buf[strspn(buf, " \t\r\n")] == '\0') continue;
        if (sscanf(buf, "%d %d", &n, &c) != 2 || n < 1 || c != cols) {
            rc = tcb_fail(err, TCB_ERR_IO, "%s:%d: expected \"<count> %d ...\"", path, line, cols);
            break;
        }
    }
    if (!rc && n < 1) rc = tcb_fail(err, TCB_ERR_IO, "%s: no header line", path);
    if (!rc && !(*out = malloc((size_t)n * cols * sizeof **out)))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory for %d rows", path, n);
    for (int r = 0; !rc && r < n;) {
        if (!fgets(buf, sizeof buf, f)) {
            rc = tcb_fail(err, TCB_ERR_IO, "%s: %d rows of %d", path, r, n);
            break;
        }
        line++;
        char *p = buf + strspn(buf, " \t");
        if (*p == '#' || *p == '\n' || *p == '\0') continue;
        char *end;
        long idx = strtol(p, &end, 10);
        if (end == p || idx != r) {
            rc = tcb_fail(err, TCB_ERR_IO, "%s:%d: expected row %d", path, line, r);
            break;
        }
        for (int k = 0; !rc && k < cols; k++) {
            p = end;
            (*out)[(size_t)r * cols + k] = strtod(p, &end);
            if (end == p) rc = tcb_fail(err, TCB_ERR_IO, "%s:%d: expected %d values", path, line, cols);
        }
        r++;
    }
    fclose(f);
    if (rc) {
        free(*out);
        *out = NULL;
    }
    *rows = rc ? 0 : n;
    return rc;
}

static double orientation(const float *v, const int32_t *t)
{
    const float *a = v + 3 * t[0], *b = v + 3 * t[1], *c = v + 3 * t[2], *d = v + 3 * t[3];
    double u[3], w[3], x[3];
    for (int k = 0; k < 3; k++) u[k] = b[k] - a[k], w[k] = c[k] - a[k], x[k] = d[k] - a[k];
    return u[0] * (w[1] * x[2] - w[2] * x[1]) - u[1] * (w[0] * x[2] - w[2] * x[0]) +
           u[2] * (w[0] * x[1] - w[1] * x[0]);
}

/* The .node and .ele tables as a tcb_tetmesh, each tet turned positive. */
static int read_result(const char *node, const char *ele, tcb_tetmesh *out, tcb_error *err)
{
    double *nv = NULL, *ev = NULL;
    int n = 0, m = 0;
    int rc = read_table(node, 3, &n, &nv, err);
    if (!rc) rc = read_table(ele, 4, &m, &ev, err);
    if (!rc && (!(out->verts = malloc((size_t)n * 3 * sizeof *out->verts)) ||
                !(out->tets = malloc((size_t)m * 4 * sizeof *out->tets))))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "tetgen: out of memory for %d tetrahedra", m);
    for (size_t i = 0; !rc && i < (size_t)n * 3; i++) out->verts[i] = (float)nv[i];
    for (int t = 0; !rc && t < m; t++) {
        int32_t *q = out->tets + 4 * (size_t)t;
        for (int k = 0; k < 4; k++) {
            double x = ev[4 * (size_t)t + k];
            if (!(x >= 0 && x < n) || x != floor(x)) {
                rc = tcb_fail(err, TCB_ERR_IO, "%s: tetrahedron %d names vertex %g of %d", ele, t, x, n);
                break;
            }
            q[k] = (int32_t)x;
        }
        if (!rc && orientation(out->verts, q) < 0) {
            int32_t s = q[2];
            q[2] = q[3], q[3] = s;
        }
    }
    free(nv), free(ev);
    out->n_verts = rc ? 0 : n, out->n_tets = rc ? 0 : m;
    if (rc) tcb_tetmesh_free(out);
    return rc;
}

int tcb_tetrahedralize(const tcb_mesh *shell, double max_volume, double radius_edge, tcb_tetmesh *out,
                       tcb_error *err)
{
    memset(out, 0, sizeof *out);
    int rc = check_shell(shell, err);
    if (rc) return rc;
    if (!(max_volume > 0) || !isfinite(max_volume))
        return tcb_fail(err, TCB_ERR_INPUT, "tetgen: a maximum volume of %g (need a positive volume)", max_volume);
    if (!(radius_edge >= 1.1) || !isfinite(radius_edge))
        return tcb_fail(err, TCB_ERR_INPUT, "tetgen: a radius-edge bound of %g (need at least 1.1)", radius_edge);
    const char *tmp = getenv("TMPDIR");
    char dir[TCB_PATH_MAX], input[TCB_PATH_MAX], log[TCB_PATH_MAX], node[TCB_PATH_MAX], ele[TCB_PATH_MAX];
    if ((rc = tcb_path_join(dir, sizeof dir, err, "%s/tcbench-tetgen-XXXXXX", tmp && *tmp ? tmp : "/tmp")))
        return rc;
    if (!mkdtemp(dir)) return tcb_fail(err, TCB_ERR_IO, "%s: cannot create: %s", dir, strerror(errno));
    rc = tcb_path_join(input, sizeof input, err, "%s/shell.smesh", dir);
    if (!rc) rc = tcb_path_join(log, sizeof log, err, "%s/tetgen.log", dir);
    if (!rc) rc = tcb_path_join(node, sizeof node, err, "%s/shell.1.node", dir);
    if (!rc) rc = tcb_path_join(ele, sizeof ele, err, "%s/shell.1.ele", dir);
    /* p: a piecewise linear complex; q, a: the bounds; z: 0-based output;
     * F: no face or edge files. Not quiet: its progress goes to the log,
     * whose last line an error quotes. */
    char switches[96];
    snprintf(switches, sizeof switches, "-pzFq%.6ga%.6g", radius_edge, max_volume);
    if (!rc) rc = write_smesh(input, shell, err);
    if (!rc) rc = run_tetgen(switches, input, log, err);
    /* An open shell has no inside: TetGen then deletes every tet and
     * writes no .ele (or crashes: run_tetgen). */
    if (!rc && !tcb_is_file(ele))
        rc = tcb_fail(err, TCB_ERR_NUMERIC, "tetgen %s left no tetrahedra: the shell is open (it has no inside)",
                      switches);
    if (!rc) rc = read_result(node, ele, out, err);
    tcb_error ignored = {0};
    tcb_empty_dir(dir, &ignored);
    rmdir(dir);
    return rc;
}
