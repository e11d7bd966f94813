/* lx_yaml.h - a YAML document as a tree in our own types (Linux only).
 *
 * lx_yaml.c is the only file that includes <yaml.h>: it lets libyaml compose the
 * document, copies it into one block of lx_yaml_node_t (scalars as NUL-terminated
 * strings) and frees libyaml's copy, so the map and scenario loaders walk plain structs.
 * Aliases resolve to the same node, as in libyaml. The tree is bounded: at most
 * LX_YAML_MAX_NODES nodes (and a file at most LX_YAML_MAX_BYTES); a larger document is
 * refused with LX_YAML_TOO_BIG. Nesting deeper than LX_YAML_MAX_DEPTH is refused as
 * LX_YAML_SYNTAX ("nesting deeper than 64 levels") before libyaml composes anything.
 */
#ifndef LX_YAML_H
#define LX_YAML_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/// Most nodes a loaded document may hold (a scenario has a few hundred).
#define LX_YAML_MAX_NODES 100000u

/// Deepest nesting of collections accepted (the root mapping is level 1; the scenario and
/// map formats need 5 at most).
#define LX_YAML_MAX_DEPTH 64
/// Largest file lx_yaml_load_file() reads, bytes (a scenario is a few kilobytes).
#define LX_YAML_MAX_BYTES (16u << 20)
/// A macro's value as a string literal (for messages).
#define LX_YAML_STR(x) LX_YAML_STR_(x)
/// Helper of LX_YAML_STR.
#define LX_YAML_STR_(x) #x

/// Kind of a node.
typedef enum lx_yaml_kind {
    LX_YAML_SCALAR,   ///< text: value
    LX_YAML_SEQUENCE, ///< n items: child[0 .. n-1]
    LX_YAML_MAPPING,  ///< n pairs: key child[2i], value child[2i + 1]
} lx_yaml_kind_t;

/// One node of a loaded document (owned by the lx_yaml_doc_t).
typedef struct lx_yaml_node {
    lx_yaml_kind_t kind;                 ///< scalar, sequence or mapping
    unsigned long line;                  ///< 1-based line where the node starts
    const char *value;                   ///< scalar text, NUL-terminated; NULL otherwise
    size_t n;                            ///< items (sequence) or pairs (mapping); 0 for a scalar
    const struct lx_yaml_node **child;   ///< n items, or 2n nodes key then value
} lx_yaml_node_t;

/// A loaded document: root is NULL for an empty stream.
typedef struct lx_yaml_doc {
    const lx_yaml_node_t *root;   ///< the document's root node, or NULL when empty
    lx_yaml_node_t *nodes;        ///< every node, one allocation
    const lx_yaml_node_t **links; ///< every child pointer, one allocation
    char *text;                   ///< every scalar's text, one allocation
} lx_yaml_doc_t;

/// Result of a load.
typedef enum lx_yaml_rc {
    LX_YAML_OK = 0,  ///< loaded
    LX_YAML_NOMEM,   ///< the parser could not start or a copy failed
    LX_YAML_SYNTAX,  ///< malformed YAML or nested too deep: line and problem set
    LX_YAML_TOO_BIG, ///< more than LX_YAML_MAX_NODES nodes or LX_YAML_MAX_BYTES bytes
} lx_yaml_rc_t;

/// Where and why a load failed (set for LX_YAML_SYNTAX).
typedef struct lx_yaml_error {
    unsigned long line;  ///< 1-based line of the problem
    const char *problem; ///< libyaml's static text naming the problem, or NULL when it gave none
} lx_yaml_error_t;

/// Load the first document of `len` bytes at `buf` into `doc` (freed with lx_yaml_free,
/// also after a failure).
lx_yaml_rc_t lx_yaml_load_string(const uint8_t *buf, size_t len, lx_yaml_doc_t *doc,
                                 lx_yaml_error_t *e);

/// Read at most max + 1 bytes of the open stream `f` into a malloc'd *buf (*len bytes; more
/// than max means the stream is longer). The buffer grows with what arrives, so a short
/// file costs little whatever max is. 0, or -1 when out of memory (*buf NULL).
int lx_yaml_read(FILE *f, size_t max, uint8_t **buf, size_t *len);

/// Load the first document read from the open stream `f` into `doc` (as above).
lx_yaml_rc_t lx_yaml_load_file(FILE *f, lx_yaml_doc_t *doc, lx_yaml_error_t *e);

/// Free what a load allocated; `doc` reads as empty afterwards.
void lx_yaml_free(lx_yaml_doc_t *doc);

/// The text of `n` when it is a scalar, else NULL (n may be NULL).
const char *lx_yaml_scalar(const lx_yaml_node_t *n);

/// The value of the first pair of mapping `m` whose key is the scalar `key`, else NULL.
const lx_yaml_node_t *lx_yaml_get(const lx_yaml_node_t *m, const char *key);

#endif /* LX_YAML_H */
