/* Parsing the scene's JSON text with jansson, out of memory included.
 *
 * jansson 2.14 does not survive every allocation failure in its parser: when its lexer
 * cannot grow its buffer it ignores the failure and then copies a string past the end
 * of a block (a crash found by tests/cli/test_alloc_fail.sh), and where it does notice,
 * the failure comes back as a syntax error. So while a parse runs on a thread, jansson
 * allocates through load_json_malloc, which on failure jumps straight out of the parse
 * (longjmp: jansson holds no lock or resource but memory there) after freeing every
 * block jansson allocated in that parse and still holds; a hash set of the parse's
 * live blocks keeps them. The caller then reports out of memory, never "invalid JSON".
 *
 * The hooks are installed once, and only over jansson's default malloc/free, so that a
 * program that gave jansson its own allocator keeps it (it then gets the syntax error
 * for an allocation failure). Outside a parse they are malloc and free, so that what
 * json_dumps returns can still be given to free().
 */
#include <pthread.h>
#include <setjmp.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "scene/load.h"

/* A parse: where to jump on failure, and the set of blocks jansson allocated in it and
 * has not freed (open addressing, linear probing, capacity a power of two, at most half
 * full). One per thread, not on the stack: it is read after the longjmp. */
typedef struct json_parse {
    jmp_buf out;
    void **slots;
    size_t cap, n;
} json_parse;

static _Thread_local json_parse json_state;
/* &json_state while a parse runs on this thread, else NULL */
static _Thread_local json_parse *json_current;

static size_t json_slot(const json_parse *p, const void *ptr)
{
    uint64_t h = (uint64_t)(uintptr_t)ptr * 0x9e3779b97f4a7c15u;
    return (size_t)(h >> 20) & (p->cap - 1);
}

static bool json_set_insert(json_parse *p, void *ptr)
{
    if (2 * (p->n + 1) > p->cap) {
        size_t cap = p->cap ? 2 * p->cap : 1024;
        void **old = p->slots, **slots = calloc(cap, sizeof *slots);
        if (!slots)
            return false;
        size_t old_cap = p->cap;
        p->slots = slots;
        p->cap = cap;
        p->n = 0;
        for (size_t i = 0; i < old_cap; i++)
            if (old[i])
                json_set_insert(p, old[i]);
        free(old);
    }
    size_t i = json_slot(p, ptr);
    while (p->slots[i])
        i = (i + 1) & (p->cap - 1);
    p->slots[i] = ptr;
    p->n++;
    return true;
}

static void json_set_remove(json_parse *p, const void *ptr)
{
    if (!p->cap)
        return;
    size_t i = json_slot(p, ptr);
    while (p->slots[i] && p->slots[i] != ptr)
        i = (i + 1) & (p->cap - 1);
    if (!p->slots[i])
        return;
    p->slots[i] = NULL;
    p->n--;
    /* backward shift: re-place the run after the hole so no lookup stops at it */
    for (size_t j = (i + 1) & (p->cap - 1); p->slots[j]; j = (j + 1) & (p->cap - 1)) {
        void *moved = p->slots[j];
        p->slots[j] = NULL;
        p->n--;
        json_set_insert(p, moved); /* cannot grow: the set just shrank */
    }
}

static void *load_json_malloc(size_t size)
{
    json_parse *p = json_current;
    void *block = malloc(size);
    if (!p)
        return block;
    if (!block)
        longjmp(p->out, 1);
    if (!json_set_insert(p, block)) {
        free(block);
        longjmp(p->out, 1);
    }
    return block;
}

static void load_json_free(void *ptr)
{
    json_parse *p = json_current;
    if (p && ptr)
        json_set_remove(p, ptr);
    free(ptr);
}

static bool json_hooked;

static void load_json_install(void)
{
    json_malloc_t m = NULL;
    json_free_t f = NULL;
    json_get_alloc_funcs(&m, &f);
    if (m == malloc && f == free) {
        json_set_alloc_funcs(load_json_malloc, load_json_free);
        json_hooked = true;
    }
}

static json_t *load_json_run(FILE *f, const char *text, json_error_t *je, bool *out_of_memory)
{
    static pthread_once_t once = PTHREAD_ONCE_INIT;
    pthread_once(&once, load_json_install);
    *out_of_memory = false;
    json_parse *parse = &json_state;
    parse->slots = NULL;
    parse->cap = parse->n = 0;
    json_t *volatile doc = NULL; /* volatile: read after longjmp */
    if (setjmp(parse->out) == 0) {
        if (json_hooked)
            json_current = parse;
        doc = f ? json_loadf(f, JSON_REJECT_DUPLICATES, je)
                : json_loads(text, JSON_REJECT_DUPLICATES, je);
    } else {
        *out_of_memory = true;
        for (size_t i = 0; i < parse->cap; i++)
            free(parse->slots[i]);
    }
    json_current = NULL;
    free(parse->slots); /* a document's blocks outlive the parse, freed by json_decref */
    if (!doc && json_error_code(je) == json_error_out_of_memory)
        *out_of_memory = true;
    return doc;
}

json_t *load_json_parse(FILE *f, const char *text, json_error_t *je, bool *out_of_memory)
{
    /* a UTF-8 byte-order mark, which some editors write first: RFC 8259 lets a parser
     * ignore it (it was refused as "'[' or '{' expected near" an invisible character) */
    static const char bom[3] = {'\xEF', '\xBB', '\xBF'};
    char head[3];
    if (f && !(fread(head, 1, 3, f) == 3 && memcmp(head, bom, 3) == 0))
        rewind(f);
    if (!f && strncmp(text, bom, 3) == 0)
        text += 3;
    return load_json_run(f, text, je, out_of_memory);
}
