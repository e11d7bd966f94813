/* lx_yaml.c - libyaml behind lx_yaml.h; the only file that includes <yaml.h>. */
#include "lx_yaml.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include <yaml.h>

/* Copy libyaml's composed document into our nodes; node ids are 1-based indices. */
static lx_yaml_rc_t copy_doc(yaml_document_t *y, lx_yaml_doc_t *doc, lx_yaml_error_t *e)
{
    size_t count = (size_t)(y->nodes.top - y->nodes.start);
    if (count == 0) {
        return LX_YAML_OK; /* empty stream: no root */
    }
    if (count > LX_YAML_MAX_NODES) {
        return LX_YAML_TOO_BIG;
    }
    size_t nlinks = 0;
    size_t ntext = 0;
    for (const yaml_node_t *n = y->nodes.start; n < y->nodes.top; n++) {
        if (n->type == YAML_SCALAR_NODE) {
            ntext += n->data.scalar.length + 1;
        } else if (n->type == YAML_SEQUENCE_NODE) {
            nlinks += (size_t)(n->data.sequence.items.top - n->data.sequence.items.start);
        } else if (n->type == YAML_MAPPING_NODE) {
            nlinks += 2 * (size_t)(n->data.mapping.pairs.top - n->data.mapping.pairs.start);
        }
    }
    doc->nodes = calloc(count, sizeof(*doc->nodes));
    doc->links = calloc(nlinks > 0 ? nlinks : 1, sizeof(const lx_yaml_node_t *));
    doc->text = malloc(ntext > 0 ? ntext : 1);
    if (doc->nodes == NULL || doc->links == NULL || doc->text == NULL) {
        return LX_YAML_NOMEM;
    }
    const lx_yaml_node_t **link = doc->links;
    char *text = doc->text;
    for (size_t i = 0; i < count; i++) {
        const yaml_node_t *n = &y->nodes.start[i];
        lx_yaml_node_t *o = &doc->nodes[i];
        o->line = (unsigned long)n->start_mark.line + 1;
        o->child = link;
        if (n->type == YAML_SCALAR_NODE) {
            o->kind = LX_YAML_SCALAR;
            memcpy(text, n->data.scalar.value, n->data.scalar.length);
            text[n->data.scalar.length] = '\0';
            o->value = text;
            text += n->data.scalar.length + 1;
            continue;
        }
        const yaml_node_item_t *ids = NULL;
        size_t nid = 0;
        if (n->type == YAML_SEQUENCE_NODE) {
            o->kind = LX_YAML_SEQUENCE;
            ids = n->data.sequence.items.start;
            nid = (size_t)(n->data.sequence.items.top - ids);
            o->n = nid;
        } else {
            o->kind = LX_YAML_MAPPING;
            o->n = (size_t)(n->data.mapping.pairs.top - n->data.mapping.pairs.start);
        }
        for (size_t k = 0; k < (ids != NULL ? nid : 2 * o->n); k++) {
            int id = ids != NULL ? ids[k]
                   : (k % 2 == 0 ? n->data.mapping.pairs.start[k / 2].key
                                 : n->data.mapping.pairs.start[k / 2].value);
            if (id < 1 || (size_t)id > count) {
                e->line = o->line;
                e->problem = "bad node reference";
                return LX_YAML_SYNTAX;
            }
            *link++ = &doc->nodes[id - 1];
        }
    }
    doc->root = &doc->nodes[0]; /* libyaml composes the root first */
    return LX_YAML_OK;
}

static lx_yaml_rc_t load(yaml_parser_t *parser, lx_yaml_doc_t *doc, lx_yaml_error_t *e)
{
    yaml_document_t y;
    if (!yaml_parser_load(parser, &y)) {
        e->line = (unsigned long)parser->problem_mark.line + 1;
        e->problem = parser->problem;
        yaml_parser_delete(parser);
        return LX_YAML_SYNTAX;
    }
    lx_yaml_rc_t rc = copy_doc(&y, doc, e);
    yaml_document_delete(&y);
    yaml_parser_delete(parser);
    return rc;
}

/* Walk the first document's events and refuse nesting deeper than LX_YAML_MAX_DEPTH
 * before libyaml composes it: composing a deep document takes time quadratic in its depth
 * (40,000 levels: seconds), and the walk stops at the first level too many. */
static lx_yaml_rc_t check_depth(const uint8_t *buf, size_t len, lx_yaml_error_t *e)
{
    yaml_parser_t parser;
    if (!yaml_parser_initialize(&parser)) {
        return LX_YAML_NOMEM;
    }
    yaml_parser_set_input_string(&parser, buf, len);
    lx_yaml_rc_t rc = LX_YAML_OK;
    unsigned depth = 0;
    bool done = false;
    while (!done) {
        yaml_event_t ev;
        if (!yaml_parser_parse(&parser, &ev)) {
            e->line = (unsigned long)parser.problem_mark.line + 1;
            e->problem = parser.problem;
            rc = LX_YAML_SYNTAX;
            break;
        }
        if (ev.type == YAML_MAPPING_START_EVENT || ev.type == YAML_SEQUENCE_START_EVENT) {
            if (++depth > LX_YAML_MAX_DEPTH) {
                e->line = (unsigned long)ev.start_mark.line + 1;
                e->problem = "nesting deeper than " LX_YAML_STR(LX_YAML_MAX_DEPTH) " levels";
                rc = LX_YAML_SYNTAX;
                done = true;
            }
        } else if (ev.type == YAML_MAPPING_END_EVENT || ev.type == YAML_SEQUENCE_END_EVENT) {
            depth--;
        } else if (ev.type == YAML_DOCUMENT_END_EVENT || ev.type == YAML_STREAM_END_EVENT) {
            done = true; /* only the first document is loaded */
        }
        yaml_event_delete(&ev);
    }
    yaml_parser_delete(&parser);
    return rc;
}

lx_yaml_rc_t lx_yaml_load_string(const uint8_t *buf, size_t len, lx_yaml_doc_t *doc,
                                 lx_yaml_error_t *e)
{
    memset(doc, 0, sizeof(*doc));
    memset(e, 0, sizeof(*e));
    lx_yaml_rc_t rc = check_depth(buf, len, e);
    if (rc != LX_YAML_OK) {
        return rc;
    }
    yaml_parser_t parser;
    if (!yaml_parser_initialize(&parser)) {
        return LX_YAML_NOMEM;
    }
    yaml_parser_set_input_string(&parser, buf, len);
    return load(&parser, doc, e);
}

int lx_yaml_read(FILE *f, size_t max, uint8_t **buf, size_t *len)
{
    /* Start small and double: a few-line file costs a few kilobytes, not `max`. */
    size_t cap = max < (1u << 12) ? max + 1 : (1u << 12);
    size_t n = 0;
    uint8_t *b = malloc(cap);
    while (b != NULL) {
        n += fread(b + n, 1, cap - n, f);
        if (n < cap || cap > max) {
            break;
        }
        const size_t grow = cap * 2 < max + 1 ? cap * 2 : max + 1;
        uint8_t *nb = realloc(b, grow);
        if (nb == NULL) {
            free(b);
        }
        b = nb;
        cap = grow;
    }
    *buf = b;
    *len = b != NULL ? n : 0;
    return b != NULL ? 0 : -1;
}

lx_yaml_rc_t lx_yaml_load_file(FILE *f, lx_yaml_doc_t *doc, lx_yaml_error_t *e)
{
    memset(doc, 0, sizeof(*doc));
    memset(e, 0, sizeof(*e));
    /* Read whole (the depth check and the load each walk it), at most LX_YAML_MAX_BYTES. */
    uint8_t *buf = NULL;
    size_t len = 0;
    if (lx_yaml_read(f, LX_YAML_MAX_BYTES, &buf, &len) != 0) {
        return LX_YAML_NOMEM;
    }
    lx_yaml_rc_t rc;
    if (ferror(f)) {
        e->line = 1;
        e->problem = "read error";
        rc = LX_YAML_SYNTAX;
    } else if (len > LX_YAML_MAX_BYTES) {
        rc = LX_YAML_TOO_BIG;
    } else {
        rc = lx_yaml_load_string(buf, len, doc, e);
    }
    free(buf);
    return rc;
}

void lx_yaml_free(lx_yaml_doc_t *doc)
{
    if (doc != NULL) {
        free(doc->nodes);
        free((void *)doc->links);
        free(doc->text);
        memset(doc, 0, sizeof(*doc));
    }
}

const char *lx_yaml_scalar(const lx_yaml_node_t *n)
{
    return n != NULL && n->kind == LX_YAML_SCALAR ? n->value : NULL;
}

const lx_yaml_node_t *lx_yaml_get(const lx_yaml_node_t *m, const char *key)
{
    if (m == NULL || m->kind != LX_YAML_MAPPING) {
        return NULL;
    }
    for (size_t i = 0; i < m->n; i++) {
        const char *ks = lx_yaml_scalar(m->child[2 * i]);
        if (ks != NULL && strcmp(ks, key) == 0) {
            return m->child[2 * i + 1];
        }
    }
    return NULL;
}
