/* The config reader (config/config.c, with the methods' and datasets'
 * keys it validates): any text as a config. A config accepted is saved
 * beside the results as its normalized JSON, which must read back to
 * itself: the run directory's config.json is what resuming compares. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz/fuzz_util.h"
#include "tcb/config.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    fuzz_require(text != NULL, "memory");
    memcpy(text, data, size);
    text[size] = '\0';
    tcb_config c;
    tcb_error err = {0};
    int rc = tcb_config_parse(text, "fuzz.json", &c, &err);
    free(text);
    fuzz_check_answer(rc, &err, "fuzz.json");
    if (rc) return 0;
    tcb_config again;
    rc = tcb_config_parse(c.json_text, "normalized.json", &again, &err);
    if (rc) fprintf(stderr, "%s\n%s\n", c.json_text, err.msg);
    fuzz_require(rc == TCB_OK, "the normalized config reads back");
    fuzz_require(strcmp(again.json_text, c.json_text) == 0, "the normalized config is a fixed point");
    tcb_config_free(&again);
    tcb_config_free(&c);
    return 0;
}
