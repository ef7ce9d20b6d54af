/* The fuzz targets without libFuzzer: runs LLVMFuzzerTestOneInput once on
 * each file named, or on each file of each directory named (not
 * recursively), in name order so that a failure reproduces. Exits 0 when
 * every input ran (a finding aborts the process, as under libFuzzer). */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz/fuzz_util.h"
#include "tcb/fsutil.h"

int LLVMFuzzerInitialize(int *argc, char ***argv) __attribute__((weak));

static int run_file(const char *path)
{
    char *data;
    size_t len;
    tcb_error err = {0};
    if (tcb_read_file(path, &data, &len, &err)) {
        fprintf(stderr, "replay: %s\n", err.msg);
        return 1;
    }
    LLVMFuzzerTestOneInput((const uint8_t *)data, len);
    free(data);
    return 0;
}

static int by_name(const struct dirent **a, const struct dirent **b) { return strcmp((*a)->d_name, (*b)->d_name); }

static int run_dir(const char *dir, int *count)
{
    struct dirent **names;
    int n = scandir(dir, &names, NULL, by_name), bad = 0;
    if (n < 0) {
        perror(dir);
        return 1;
    }
    for (int k = 0; k < n; k++) {
        char path[TCB_PATH_MAX];
        snprintf(path, sizeof path, "%s/%s", dir, names[k]->d_name);
        if (names[k]->d_name[0] != '.' && tcb_is_file(path)) bad |= run_file(path), (*count)++;
        free(names[k]);
    }
    free(names);
    return bad;
}

int main(int argc, char **argv)
{
    if (LLVMFuzzerInitialize) LLVMFuzzerInitialize(&argc, &argv);
    int bad = 0, count = 0;
    for (int k = 1; k < argc; k++) {
        if (tcb_is_dir(argv[k])) bad |= run_dir(argv[k], &count);
        else bad |= run_file(argv[k]), count++;
    }
    printf("replayed %d inputs\n", count);
    return bad;
}
