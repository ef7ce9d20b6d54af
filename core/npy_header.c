/* The .npy header: a Python dict literal, parsed by hand.
 *
 * numpy writes the header with repr() and reads it back with
 * ast.literal_eval. No C library parses Python literals, and a general one
 * would accept far more than a header may hold, so this is a small
 * recursive-descent parser for exactly what a header is: a dict of the three
 * string keys 'descr', 'fortran_order' and 'shape', each once, whose values
 * are a string, True or False, and a tuple of non-negative integers, with
 * Python's whitespace and trailing commas. Anything else is an error that
 * says what was expected at which byte of the header.
 *
 * Bytes >= 0x80 occur only in the field names of structured dtypes (the
 * reason version 3.0 made the header utf-8), which are refused anyway, so
 * one ASCII parser serves every version. */
#include "core/npy_header.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#define N_KEYS 3
static const char *const KEYS[N_KEYS] = {"descr", "fortran_order", "shape"};

typedef struct cursor {
    const char *text;
    size_t pos, len;
} cursor;

static int peek(const cursor *c) { return c->pos < c->len ? (unsigned char)c->text[c->pos] : -1; }

/* Python's whitespace between tokens (inside brackets newlines count too). */
static void skip_ws(cursor *c)
{
    for (int ch; (ch = peek(c)) == ' ' || ch == '\t' || ch == '\n' || ch == '\r' || ch == '\f';) c->pos++;
}

__attribute__((format(printf, 3, 4))) static int bad(const cursor *c, tcb_error *err, const char *fmt, ...)
{
    char what[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    if (c->pos >= c->len)
        return tcb_fail(err, TCB_ERR_INPUT, "header: %s, but the header ends (after %zu bytes)", what, c->len);
    return tcb_fail(err, TCB_ERR_INPUT, "header: %s at byte %zu", what, c->pos);
}

/* 'text' or "text": printable ASCII, no escapes (no header needs one). */
static int parse_string(cursor *c, const char *what, char *out, size_t size, tcb_error *err)
{
    int quote = peek(c);
    if (quote != '\'' && quote != '"') return bad(c, err, "expected a string as %s", what);
    size_t start = ++c->pos;
    for (int ch; (ch = peek(c)) != quote; c->pos++) {
        if (ch < 0x20 || ch > 0x7e) {
            if (ch < 0) return bad(c, err, "unterminated string");
            return bad(c, err, "byte 0x%02x in a string (only ASCII names are read)", (unsigned)ch);
        }
        if (ch == '\\') return bad(c, err, "escape sequence in a string");
    }
    size_t n = c->pos - start;
    c->pos++;
    if (n >= size) return bad(c, err, "%s longer than %zu characters", what, size - 1);
    memcpy(out, c->text + start, n);
    out[n] = '\0';
    return TCB_OK;
}

static int is_name_char(int ch) { return ch == '_' || (ch >= '0' && ch <= '9') || ((ch | 32) >= 'a' && (ch | 32) <= 'z'); }

static int parse_bool(cursor *c, int *out, tcb_error *err)
{
    size_t start = c->pos;
    while (is_name_char(peek(c))) c->pos++;
    size_t n = c->pos - start;
    if (n == 4 && !memcmp(c->text + start, "True", 4)) return *out = 1, TCB_OK;
    if (n == 5 && !memcmp(c->text + start, "False", 5)) return *out = 0, TCB_OK;
    c->pos = start;
    return bad(c, err, "'fortran_order': expected True or False");
}

/* A Python integer literal >= 0 that fits numpy's npy_intp (int64). */
static int parse_dim(cursor *c, uint64_t *out, tcb_error *err)
{
    int ch = peek(c);
    if (ch == '-') return bad(c, err, "'shape': negative dimension");
    if (ch < '0' || ch > '9') return bad(c, err, "'shape': expected a non-negative integer");
    size_t start = c->pos;
    uint64_t v = 0;
    for (; (ch = peek(c)) >= '0' && ch <= '9'; c->pos++) {
        if (v > ((uint64_t)INT64_MAX - (uint64_t)(ch - '0')) / 10) {
            c->pos = start;
            return bad(c, err, "'shape': dimension larger than 2^63 - 1");
        }
        v = 10 * v + (uint64_t)(ch - '0');
    }
    if (c->text[start] == '0' && c->pos - start > 1) {
        c->pos = start;
        return bad(c, err, "'shape': leading zero (not a Python integer)");
    }
    if (is_name_char(peek(c)) || peek(c) == '.')
        return bad(c, err, "'shape': malformed integer (no suffixes, underscores or fractions)");
    *out = v;
    return TCB_OK;
}

/* (), (n,), (n, m), (n, m,) ...: a one-element tuple needs its comma,
 * since "(5)" is the number 5 in Python (numpy refuses it too). */
static int parse_shape(cursor *c, tcb_npy *out, tcb_error *err)
{
    if (peek(c) != '(') return bad(c, err, "'shape': expected a tuple such as (500, 3)");
    c->pos++;
    out->ndim = 0;
    int comma = 0;
    for (;;) {
        skip_ws(c);
        if (peek(c) == ')') break;
        if (out->ndim > 0 && !comma) return bad(c, err, "'shape': expected ',' or ')'");
        if (out->ndim == TCB_NPY_MAX_DIMS) return bad(c, err, "'shape': more than %d dimensions", TCB_NPY_MAX_DIMS);
        int rc = parse_dim(c, &out->shape[out->ndim++], err);
        if (rc) return rc;
        skip_ws(c);
        if ((comma = peek(c) == ',')) c->pos++;
    }
    if (out->ndim == 1 && !comma)
        return bad(c, err, "'shape': (%llu) is a number, not a tuple (a 1-d shape is written (%llu,))",
                   (unsigned long long)out->shape[0], (unsigned long long)out->shape[0]);
    c->pos++;
    return TCB_OK;
}

/* "<f8": byte order, kind, size; only what numpy writes for the types read. */
static int set_dtype(const cursor *c, const char *d, tcb_npy *out, tcb_error *err)
{
    if (d[0] == '=')
        return bad(c, err, "'descr': '%s': native byte order '=' does not say the writer's", d);
    if (strlen(d) != 3 || !strchr("<>|", d[0]) || !strchr("biuf", d[1]) || !strchr("1248", d[2]) ||
        (d[1] == 'b' && d[2] != '1') || (d[1] == 'f' && d[2] < '2'))
        return bad(c, err, "'descr': dtype '%s' is not supported (read: b1, i1 i2 i4 i8, u1 u2 u4 u8, "
                           "f2 f4 f8, each after '<', '>' or '|')", d);
    if (d[0] == '|' && d[2] != '1')
        return bad(c, err, "'descr': '%s': byte order '|' (not applicable) on a multi-byte type", d);
    snprintf(out->descr, sizeof out->descr, "%s", d);
    out->kind = d[1];
    out->item_size = d[2] - '0';
    out->big_endian = d[0] == '>' && out->item_size > 1;
    return TCB_OK;
}

static int parse_value(cursor *c, int key, tcb_npy *out, tcb_error *err)
{
    if (key == 1) return parse_bool(c, &out->fortran_order, err);
    if (key == 2) return parse_shape(c, out, err);
    if (peek(c) == '[') return bad(c, err, "'descr': structured dtypes (a list of fields) are not supported");
    char d[64];
    cursor at = *c;
    int rc = parse_string(c, "'descr'", d, sizeof d, err);
    return rc ? rc : set_dtype(&at, d, out, err);
}

static int parse_entry(cursor *c, unsigned *seen, tcb_npy *out, tcb_error *err)
{
    char key[64];
    cursor at = *c;
    int rc = parse_string(c, "key", key, sizeof key, err);
    if (rc) return rc;
    int k = 0;
    while (k < N_KEYS && strcmp(key, KEYS[k])) k++;
    if (k == N_KEYS)
        return bad(&at, err, "unexpected key '%s' (a header has 'descr', 'fortran_order' and 'shape')", key);
    if (*seen & 1u << k) return bad(&at, err, "'%s' given twice", key);
    *seen |= 1u << k;
    skip_ws(c);
    if (peek(c) != ':') return bad(c, err, "expected ':' after '%s'", key);
    c->pos++;
    skip_ws(c);
    return parse_value(c, k, out, err);
}

int tcb_npy_parse_header(const char *text, size_t len, tcb_npy *out, tcb_error *err)
{
    cursor c = {text, 0, len};
    unsigned seen = 0;
    int comma = 1;
    skip_ws(&c);
    if (peek(&c) != '{') return bad(&c, err, "expected '{' (a Python dict)");
    c.pos++;
    for (;;) {
        skip_ws(&c);
        if (peek(&c) == '}') break;
        if (!comma) return bad(&c, err, "expected ',' or '}'");
        int rc = parse_entry(&c, &seen, out, err);
        if (rc) return rc;
        skip_ws(&c);
        if ((comma = peek(&c) == ',')) c.pos++;
    }
    c.pos++;
    for (int k = 0; k < N_KEYS; k++)
        if (!(seen & 1u << k)) return tcb_fail(err, TCB_ERR_INPUT, "header: no '%s' key", KEYS[k]);
    skip_ws(&c);
    if (c.pos < c.len) return bad(&c, err, "text after the dict");
    return TCB_OK;
}
