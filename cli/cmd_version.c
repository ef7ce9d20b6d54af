/* `tcbench version`. */
#include <stdio.h>

#include "cli/cli.h"
#include "tcb/sysinfo.h"
#include "tcb/version.h"

static int cmd_version(const cli_args *c)
{
    (void)c;
    char rev[64];
    tcb_git_revision(rev, sizeof rev);
    printf("tcbench %s (git %s)\n", TCB_VERSION, rev);
    return 0;
}

const cli_command cli_version = {
    .name = "version", .fn = cmd_version, .min_args = 0, .max_args = 0, .arg_names = "",
    .accepts = 0,
    .summary = "print the version",
    .usage =
        "usage: tcbench version\n"
        "\n"
        "Prints the tcbench version and the git revision of its source tree.\n"
        "\n"
        "example:\n"
        "  tcbench version\n"
};
