/* Parsing the scene's JSON text with jansson, out of memory included.
 *
 * jansson 2.14 does not survive every allocation failure in its parser: when its lexer
 * cannot grow its buffer it ignores the failure and then copies a string past the end
 * of a block (a crash found by tests/cli/test_alloc_fail.sh), and where it does notice,
 * the failure comes back as a syntax error. So while a parse runs on a thread, jansson
 * allocates through load_json_malloc, which on failure jumps straight out of the parse
 * (longjmp: jansson holds no lock or resource but memory there) and frees every block
 * jansson allocated in that parse, which it tracks in a list. The caller then reports
 * out of memory, never "invalid JSON".
 *
 * The hook is installed once, and only over jansson's default malloc/free, so that a
 * program that gave jansson its own allocator keeps it (it then gets the syntax error
 * for an allocation failure). Blocks carry a small header for the list; outside a
 * parse it is unused.
 */
#include <pthread.h>
#include <setjmp.h>
#include <stdalign.h>
#include <stdbool.h>
#include <stdlib.h>

#include "scene/load.h"

/* Links in the list of a parse's blocks (both NULL: in no list). */
typedef struct json_link {
    struct json_link *prev, *next;
} json_link;

/* The header before each block jansson gets. */
typedef struct json_block {
    json_link link; /* first: a json_link * of a block is the block */
    alignas(max_align_t) unsigned char data[];
} json_block;

/* The parse running on this thread (NULL: none). */
typedef struct json_parse {
    jmp_buf out;
    json_link head; /* sentinel of the list of live blocks allocated in the parse */
} json_parse;

static _Thread_local json_parse *json_current;

static void *load_json_malloc(size_t size)
{
    json_parse *p = json_current;
    json_block *b = size <= SIZE_MAX - sizeof *b ? malloc(sizeof *b + size) : NULL;
    if (!b) {
        if (p)
            longjmp(p->out, 1);
        return NULL;
    }
    b->link.prev = b->link.next = NULL;
    if (p) {
        b->link.next = p->head.next;
        b->link.prev = &p->head;
        p->head.next->prev = &b->link;
        p->head.next = &b->link;
    }
    return b->data;
}

static void load_json_free(void *ptr)
{
    if (!ptr)
        return;
    json_block *b = (json_block *)((unsigned char *)ptr - offsetof(json_block, data));
    if (b->link.next) { /* in the list of the parse running on this thread */
        b->link.prev->next = b->link.next;
        b->link.next->prev = b->link.prev;
    }
    free(b);
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

json_t *load_json_parse(FILE *f, const char *text, json_error_t *je, bool *out_of_memory)
{
    static pthread_once_t once = PTHREAD_ONCE_INIT;
    pthread_once(&once, load_json_install);
    *out_of_memory = false;
    json_parse parse;
    parse.head.prev = parse.head.next = &parse.head;
    /* volatile: read after longjmp */
    json_t *volatile doc = NULL;
    if (setjmp(parse.out) == 0) {
        if (json_hooked)
            json_current = &parse;
        doc = f ? json_loadf(f, JSON_REJECT_DUPLICATES, je)
                : json_loads(text, JSON_REJECT_DUPLICATES, je);
    } else {
        *out_of_memory = true;
        while (parse.head.next != &parse.head) {
            json_link *b = parse.head.next;
            parse.head.next = b->next;
            free(b);
        }
        parse.head.prev = &parse.head;
    }
    json_current = NULL;
    /* the document's blocks outlive the parse: take them out of its list */
    for (json_link *b = parse.head.next, *next; b != &parse.head; b = next) {
        next = b->next;
        b->prev = b->next = NULL;
    }
    if (!doc && json_error_code(je) == json_error_out_of_memory)
        *out_of_memory = true;
    return doc;
}
