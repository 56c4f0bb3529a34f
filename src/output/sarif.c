/* Builds a SARIF 2.1.0 log with jansson. Positions keep pfx's meaning:
 * 1-based lines, and columns counted in Unicode characters (libyaml's
 * count), which the run declares with columnKind "unicodeCodePoints"; a
 * region ends at the column after the underlined span, as SARIF's
 * endColumn does. File URIs are relative to %SRCROOT%, the current
 * directory, where they can be. It does not write files: the caller picks
 * the stream. */
#include "output/sarif.h"

#include <jansson.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define SARIF_SCHEMA                                                                               \
    "https://docs.oasis-open.org/sarif/sarif/v2.1.0/errata01/os/schemas/sarif-schema-2.1.0.json"

struct pfx_sarif {
    json_t *log;
    json_t *results; /* borrowed from log */
    char *root;      /* %SRCROOT%: the current directory, ending in '/'; NULL if unknown */
};

/* A JSON string of s. jansson refuses bytes that are not UTF-8 (a file
 * name from a Latin-1 system); those become '?', so the log stays valid
 * rather than losing the diagnostic. */
static json_t *text(const char *s) {
    json_t *j = json_string(s);
    if (j)
        return j;
    char *copy = strdup(s);
    if (!copy)
        return NULL;
    for (char *p = copy; *p; p++)
        if ((unsigned char)*p >= 0x80)
            *p = '?';
    j = json_string(copy);
    free(copy);
    return j;
}

/* path percent-encoded as a URI path: bytes outside RFC 3986's
 * unreserved set and '/' become %XX. prefix goes first, as it is. */
static char *uri_encode(const char *prefix, const char *path) {
    size_t n = strlen(path);
    char *uri = malloc(strlen(prefix) + 3 * n + 1);
    if (!uri)
        return NULL;
    char *o = uri + sprintf(uri, "%s", prefix);
    for (const unsigned char *p = (const unsigned char *)path; *p; p++) {
        if ((*p >= 'A' && *p <= 'Z') || (*p >= 'a' && *p <= 'z') || (*p >= '0' && *p <= '9') ||
            strchr("-._~/", *p))
            *o++ = (char)*p;
        else
            o += sprintf(o, "%%%02X", *p);
    }
    *o = 0;
    return uri;
}

/* The artifact location of path. Code scanning services resolve a URI
 * against %SRCROOT%, which pfx sets to the current directory (where CI runs
 * it, the checkout's root): a relative path stays as given, relative to
 * it, and so does an absolute one inside it (after resolving symbolic
 * links); an absolute path elsewhere is a file: URI of its own. */
static json_t *artifact_location(const char *path, const char *root) {
    const char *rel = path[0] == '/' ? NULL : path;
    char real[PATH_MAX];
    if (!rel && root && realpath(path, real) && !strncmp(real, root, strlen(root)))
        rel = real + strlen(root);
    char *uri = rel ? uri_encode("", rel) : uri_encode("file://", path);
    json_t *j =
        uri ? json_pack(rel ? "{s:s, s:s}" : "{s:s}", "uri", uri, "uriBaseId", "%SRCROOT%") : NULL;
    free(uri);
    return j;
}

static const char *level(pfx_severity s) {
    return s == PFX_SEV_ERROR ? "error" : s == PFX_SEV_WARNING ? "warning" : "note";
}

/* A location object: the file and, when the diagnostic has one, the
 * region; NULL for a runtime failure, which has no file. */
static json_t *location(const pfx_diags *d, const pfx_diag *g, const char *root) {
    if (!d->file)
        return NULL;
    json_t *phys = json_pack("{s:o}", "artifactLocation", artifact_location(d->file, root));
    if (phys && g->line > 0)
        json_object_set_new(phys, "region",
                            json_pack("{s:i, s:i, s:i}", "startLine", g->line, "startColumn",
                                      g->col > 0 ? g->col : 1, "endColumn",
                                      (g->col > 0 ? g->col : 1) + (g->span > 0 ? g->span : 1)));
    return phys ? json_pack("{s:o}", "physicalLocation", phys) : NULL;
}

static json_t *rule_index(pfx_rule rule) {
    const pfx_rule_info *info = pfx_rule_find(rule);
    return info ? json_integer(info - pfx_rules) : NULL;
}

/* One result for the error or warning g (or a note with no head). */
static json_t *result(const pfx_diags *d, const pfx_diag *g, const char *root) {
    json_t *r = json_object();
    if (!r)
        return NULL;
    json_t *index = rule_index(g->rule);
    if (index) {
        char id[16];
        json_object_set_new(r, "ruleId", json_string(pfx_rule_id(g->rule, id, sizeof id)));
        json_object_set_new(r, "ruleIndex", index);
    }
    if (json_object_set_new(r, "level", json_string(level(g->severity))) ||
        json_object_set_new(r, "message", json_pack("{s:o}", "text", text(g->message)))) {
        json_decref(r);
        return NULL;
    }
    json_t *loc = location(d, g, root);
    if (loc)
        json_object_set_new(r, "locations", json_pack("[o]", loc));
    /* A warning the file's `allow:` acknowledges: in the log, as code
     * scanning shows a dismissed alert, with the file's reason. */
    if (g->allowed)
        json_object_set_new(
            r, "suppressions",
            json_pack("[{s:s, s:o}]", "kind", "inSource", "justification", text(g->allowed)));
    return r;
}

/* A note of result r: a related location with the note's message, and the
 * note's position when it has one. */
static bool add_note(json_t *r, const pfx_diags *d, const pfx_diag *g, const char *root) {
    json_t *related = json_object_get(r, "relatedLocations");
    if (!related) {
        related = json_array();
        if (json_object_set_new(r, "relatedLocations", related))
            return false;
    }
    json_t *loc = location(d, g, root);
    if (!loc)
        loc = json_object();
    if (!loc)
        return false;
    if (json_object_set_new(loc, "id", json_integer((json_int_t)json_array_size(related))) ||
        json_object_set_new(loc, "message", json_pack("{s:o}", "text", text(g->message)))) {
        json_decref(loc);
        return false;
    }
    return json_array_append_new(related, loc) == 0;
}

static json_t *rules_array(void) {
    json_t *rules = json_array();
    for (size_t i = 0; rules && i < pfx_rule_count; i++) {
        const pfx_rule_info *info = &pfx_rules[i];
        char id[16];
        json_t *row = json_pack("{s:s, s:s, s:{s:s}, s:{s:s}, s:{s:s}}", "id",
                                pfx_rule_id(info->rule, id, sizeof id), "name", info->name,
                                "shortDescription", "text", info->help, "fullDescription", "text",
                                info->help, "defaultConfiguration", "level", level(info->severity));
        if (json_array_append_new(rules, row)) {
            json_decref(rules);
            return NULL;
        }
    }
    return rules;
}

pfx_sarif *pfx_sarif_create(void) {
    pfx_sarif *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    s->log = json_pack("{s:s, s:s, s:[{s:{s:{s:s, s:s, s:o}}, s:s, s:[]}]}", "$schema",
                       SARIF_SCHEMA, "version", "2.1.0", "runs", "tool", "driver", "name", "pfx",
                       "version", PFX_VERSION, "rules", rules_array(), "columnKind",
                       "unicodeCodePoints", "results");
    if (!s->log) {
        free(s);
        return NULL;
    }
    json_t *run = json_array_get(json_object_get(s->log, "runs"), 0);
    s->results = json_object_get(run, "results");
    /* %SRCROOT%, the base of relative URIs: the current directory. */
    char cwd[PATH_MAX];
    if (getcwd(cwd, sizeof cwd - 1)) {
        if (strcmp(cwd, "/"))
            strcat(cwd, "/");
        s->root = strdup(cwd);
        char *uri = s->root ? uri_encode("file://", cwd) : NULL;
        if (!uri || json_object_set_new(run, "originalUriBaseIds",
                                        json_pack("{s:{s:s}}", "%SRCROOT%", "uri", uri))) {
            free(uri);
            pfx_sarif_destroy(s);
            return NULL;
        }
        free(uri);
    }
    return s;
}

void pfx_sarif_destroy(pfx_sarif *s) {
    if (!s)
        return;
    json_decref(s->log);
    free(s->root);
    free(s);
}

bool pfx_sarif_add(pfx_sarif *s, const pfx_diags *d) {
    size_t *order = pfx_diags_order(d);
    if (!order && d->count)
        return false;
    bool ok = true;
    json_t *last = NULL; /* the result a note belongs to */
    for (size_t k = 0; ok && k < d->count; k++) {
        const pfx_diag *g = &d->items[order[k]];
        if (g->severity == PFX_SEV_NOTE && last) {
            ok = add_note(last, d, g, s->root);
            continue;
        }
        last = result(d, g, s->root);
        ok = last && json_array_append_new(s->results, last) == 0;
    }
    free(order);
    return ok;
}

bool pfx_sarif_write(const pfx_sarif *s, FILE *out) {
    return json_dumpf(s->log, out, JSON_INDENT(2) | JSON_PRESERVE_ORDER) == 0 &&
           fputc('\n', out) != EOF && fflush(out) == 0;
}
