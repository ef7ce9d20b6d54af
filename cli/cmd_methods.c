/* `tcbench methods`: the registered methods, built in and loaded from
 * plug-ins. */
#include <stdio.h>
#include <string.h>

#include "cli/cli.h"
#include "tcb/registry.h"

static int cmd_methods(const cli_args *c)
{
    (void)c;
    int wn = 4, wo = 6;
    for (int k = 0; k < tcb_registry_count(); k++) {
        int n = (int)strlen(tcb_registry_get(k)->name), o = (int)strlen(tcb_registry_origin(k));
        wn = n > wn ? n : wn;
        wo = o > wo ? o : wo;
    }
    printf("%-*s  %-*s  %s\n", wn, "NAME", wo, "ORIGIN", "DESCRIPTION");
    for (int k = 0; k < tcb_registry_count(); k++) {
        const tcb_method_ops *m = tcb_registry_get(k);
        printf("%-*s  %-*s  %s\n", wn, m->name, wo, tcb_registry_origin(k),
               m->description ? m->description : "");
    }
    return 0;
}

const cli_command cli_methods = {
    .name = "methods", .fn = cmd_methods, .min_args = 0, .max_args = 0, .arg_names = "",
    .accepts = 0,
    .summary = "list the registered methods",
    .usage =
        "usage: tcbench methods [--plugin SO]...\n"
        "\n"
        "Lists the registered methods: name, origin (built-in or plug-in path) and\n"
        "description.\n"
        "\n"
        "options:\n"
        "  --plugin SO  also load the methods of this plug-in (repeatable)\n"
        "\n"
        "example:\n"
        "  tcbench methods --plugin build/examples/libmy_method.so\n"
};
