/* `pfx schema`: the JSON Schema (2020-12) of the effect format, written from
 * the key tables. Each row becomes a property (its type, range, default and
 * description); each table a definition; each kinded family (forces,
 * shapes, deflectors, regions) a `type`-discriminated choice of its kinds'
 * tables. Syntaxes that code reads (a random value, a colour, a gradient)
 * are fragments beside their readers' rows. Each property carries the
 * row's text for editors (title, description, markdownDescription: the
 * text pfx lsp's hover shows, from compile/key_doc.c) and each colour form
 * a colour's error message. JSON goes through jansson. */
#include "compile/schema.h"

#include <jansson.h>
#include <math.h>
#include <string.h>

#include "compile/key_doc.h"
#include "compile/keys.h"
#include "compile/read.h"

static json_t *parse_fragment(const char *text) {
    json_error_t err;
    json_t *j = json_loads(text, 0, &err);
    return j ? j : json_object();
}

/* A number as JSON: an integer when it is one (and fits), else a real. */
static json_t *number(double x) {
    if (x == floor(x) && fabs(x) < 9e15)
        return json_integer((json_int_t)x);
    return json_real(x);
}

static void add_range(json_t *p, const pfx_key *k) {
    if (isfinite(k->lo))
        json_object_set_new(p, (k->flags & PFX_KEY_LO_STRICT) ? "exclusiveMinimum" : "minimum",
                            number(k->lo));
    if (isfinite(k->hi))
        json_object_set_new(p, (k->flags & PFX_KEY_HI_STRICT) ? "exclusiveMaximum" : "maximum",
                            number(k->hi));
}

static json_t *names_array(const char *const *names) {
    json_t *a = json_array();
    for (size_t i = 0; names[i]; i++)
        json_array_append_new(a, json_string(names[i]));
    return a;
}

static json_t *ref(const char *def) {
    char buf[128];
    snprintf(buf, sizeof buf, "#/$defs/%s", def);
    json_t *j = json_object();
    json_object_set_new(j, "$ref", json_string(buf));
    return j;
}

static json_t *vec3_schema(double limit) {
    if (!(limit > 0))
        return ref("vec3");
    json_t *p = json_object(), *items = json_object();
    json_object_set_new(p, "type", json_string("array"));
    json_object_set_new(items, "type", json_string("number"));
    json_object_set_new(items, "minimum", number(-limit));
    json_object_set_new(items, "maximum", number(limit));
    json_object_set_new(p, "items", items);
    json_object_set_new(p, "minItems", json_integer(3));
    json_object_set_new(p, "maxItems", json_integer(3));
    return p;
}

/* A number or whole row: its type, range and default. */
static json_t *number_schema(const pfx_key *k, bool def) {
    json_t *p = json_object();
    json_object_set_new(p, "type", json_string(k->type == PFX_KEY_NUMBER ? "number" : "integer"));
    add_range(p, k);
    if (def)
        json_object_set_new(p, "default", number(k->def[0]));
    return p;
}

static json_t *bool_schema(const pfx_key *k, bool def) {
    json_t *p = json_object();
    json_object_set_new(p, "type", json_string("boolean"));
    if (def)
        json_object_set_new(p, "default", json_boolean(k->def[0] != 0));
    return p;
}

/* A vec3 row: three bounded numbers, not all zero where the row says so. */
static json_t *vec3_row_schema(const pfx_key *k, bool def) {
    json_t *p = vec3_schema(k->hi);
    if (k->flags & PFX_KEY_NONZERO)
        json_object_set_new(p, "not", json_pack("{s:{s:i}}", "items", "const", 0));
    if (def) {
        json_t *d = json_array();
        for (int i = 0; i < 3; i++)
            json_array_append_new(d, number(k->def[i]));
        json_object_set_new(p, "default", d);
    }
    return p;
}

static json_t *enum_schema(const pfx_key *k, bool def) {
    json_t *p = json_object();
    json_object_set_new(p, "enum", names_array(k->names));
    if (def)
        json_object_set_new(p, "default", json_string(pfx_kind_name(k->names, (int)k->def[0])));
    return p;
}

/* A value row: the shared "value" definition, with the row's range applied
 * to the number, each end of [min, max], the mean and the clamp. */
static json_t *value_schema(const pfx_key *k, bool def) {
    json_t *p = ref("value");
    add_range(p, k);
    if (isfinite(k->lo) || isfinite(k->hi)) {
        json_t *bound = json_object(), *props = json_object(), *clamp = json_object();
        add_range(bound, k);
        json_object_set_new(p, "items", json_deep_copy(bound));
        json_object_set_new(props, "mean", json_deep_copy(bound));
        json_object_set_new(clamp, "items", bound);
        json_object_set_new(props, "clamp", clamp);
        json_object_set_new(p, "properties", props);
    }
    if (def)
        json_object_set_new(p, "default", number(k->def[0]));
    return p;
}

/* A range row: a number, [min, max] or {mean, var}, every number within
 * the row's range. */
static json_t *range_schema(const pfx_key *k, bool def) {
    json_t *num = json_object(), *arr = json_object(), *mv = json_object(), *props,
           *one = json_array();
    json_object_set_new(num, "type", json_string("number"));
    add_range(num, k);
    json_object_set_new(arr, "type", json_string("array"));
    json_object_set_new(arr, "items", json_deep_copy(num));
    json_object_set_new(arr, "minItems", json_integer(2));
    json_object_set_new(arr, "maxItems", json_integer(2));
    json_object_set_new(mv, "type", json_string("object"));
    json_object_set_new(mv, "required", json_pack("[s]", "mean"));
    json_object_set_new(mv, "additionalProperties", json_false());
    props = json_object();
    json_object_set_new(props, "mean", json_deep_copy(num));
    json_object_set_new(props, "var", json_deep_copy(num));
    json_object_set_new(mv, "properties", props);
    json_array_append_new(one, num);
    json_array_append_new(one, arr);
    json_array_append_new(one, mv);
    json_t *p = json_object();
    if (def)
        json_object_set_new(p, "default", number(k->def[0]));
    json_object_set_new(p, "oneOf", one);
    return p;
}

/* The schema of one row (without its description). */
static json_t *row_schema(const pfx_key_table *t, const pfx_key *k) {
    const bool def = !(k->flags & PFX_KEY_NO_DEFAULT);
    if (t->kind && !strcmp(k->name, "type")) {
        json_t *p = json_object();
        json_object_set_new(p, "const", json_string(t->kind));
        return p;
    }
    if (k->schema && k->type != PFX_KEY_COLOUR && k->type != PFX_KEY_CODE)
        return parse_fragment(k->schema); /* a row whose syntax is richer than its type */
    switch (k->type) {
    case PFX_KEY_NUMBER:
    case PFX_KEY_WHOLE:
        return number_schema(k, def);
    case PFX_KEY_BOOL:
        return bool_schema(k, def);
    case PFX_KEY_VEC3:
        return vec3_row_schema(k, def);
    case PFX_KEY_ENUM:
        return enum_schema(k, def);
    case PFX_KEY_VALUE:
        return value_schema(k, def);
    case PFX_KEY_RANGE:
        return range_schema(k, def);
    case PFX_KEY_STRING: {
        json_t *p = json_object();
        json_object_set_new(p, "type", json_string("string"));
        return p;
    }
    case PFX_KEY_MAP:
        return ref(k->table->name);
    case PFX_KEY_COLOUR:
    case PFX_KEY_CODE:
    default:
        return k->schema ? parse_fragment(k->schema) : json_object();
    }
}

/* What a table is: its doc, or for one kind's table its type row's. */
static const char *table_doc(const pfx_key_table *t) {
    if (t->doc)
        return t->doc;
    const pfx_key *type = t->kind ? pfx_keys_find(t, "type") : NULL;
    return type ? type->doc : NULL;
}

/* The descriptions of the forms a property's value may take: its oneOf
 * branches, or those of the fragment it refers to (a branch without one
 * says it through the definition it refers to). */
static json_t *forms_of(json_t *p, json_t *fragments) {
    json_t *one = json_object_get(p, "oneOf");
    const char *r = json_string_value(json_object_get(p, "$ref"));
    if (!one && r && !strncmp(r, "#/$defs/", 8))
        one = json_object_get(json_object_get(fragments, r + 8), "oneOf");
    return one;
}

static const char *form_doc(json_t *branch, json_t *fragments) {
    const char *d = json_string_value(json_object_get(branch, "description"));
    const char *r = json_string_value(json_object_get(branch, "$ref"));
    if (!d && r && !strncmp(r, "#/$defs/", 8))
        d = json_string_value(json_object_get(json_object_get(fragments, r + 8), "description"));
    return d;
}

/* The first sentence of a doc, as a title. */
static json_t *first_sentence(const char *doc) {
    size_t n = 0;
    while (doc[n] &&
           !(doc[n] == '.' && doc[n + 1] == ' ' && doc[n + 2] >= 'A' && doc[n + 2] <= 'Z'))
        n++;
    return json_stringn(doc, doc[n] ? n + 1 : n);
}

/* md (of length m, in size bytes) with the forms' descriptions after it. */
static void put_forms(char *md, size_t m, size_t size, json_t *form, json_t *fragments) {
    json_t *branch;
    size_t i;
    json_array_foreach(forms_of(form, fragments), i, branch) {
        const char *d = form_doc(branch, fragments);
        if (d && m < size)
            m += (size_t)snprintf(md + m, size - m, "%s- %s", i ? "\n" : "\n\nForms:\n\n", d);
    }
}

/* A property's annotations. yaml-language-server's hover shows the first
 * title and the first (markdown)Description among the schemas the value
 * matched, innermost first, and a schema without a title inherits its
 * parent's: so the title, the meaning with its unit, heads the hover and
 * the matched form's description follows it. description and
 * markdownDescription are the whole text (for a row, pfx lsp's hover:
 * meaning, form, range, default), the markdown one with the forms'
 * descriptions after. */
static void annotate(json_t *p, const pfx_key *k, json_t *form, json_t *fragments) {
    char text[2048], md[4096];
    json_object_set_new(p, "title", first_sentence(k->doc));
    pfx_key_doc(k, false, text, sizeof text);
    json_object_set_new(p, "description", json_string(text));
    put_forms(md, pfx_key_doc(k, true, md, sizeof md), sizeof md, form, fragments);
    json_object_set_new(p, "markdownDescription", json_string(md));
}

/* The same for the properties of the hand-written fragments (a burst's
 * count, a gradient stop's colour), whose text is their description. */
static void annotate_fragment(json_t *node, json_t *fragments) {
    json_t *props = json_object_get(node, "properties"), *v;
    const char *key;
    size_t i;
    json_object_foreach(props, key, v) {
        const char *d = json_string_value(json_object_get(v, "description"));
        if (d && !json_object_get(v, "title")) {
            char md[4096];
            snprintf(md, sizeof md, "%s", d);
            put_forms(md, strlen(md), sizeof md, v, fragments);
            json_object_set_new(v, "title", first_sentence(d));
            json_object_set_new(v, "markdownDescription", json_string(md));
        }
    }
    if (json_is_object(node))
        json_object_foreach(node, key, v) annotate_fragment(v, fragments);
    else if (json_is_array(node))
        json_array_foreach(node, i, v) annotate_fragment(v, fragments);
}

/* A table as an object schema: its rows as properties, its extra rules. */
static json_t *table_schema(const pfx_key_table *t, json_t *fragments) {
    json_t *o = json_object(), *props = json_object(), *req = json_array();
    const char *doc = table_doc(t);
    if (doc)
        json_object_set_new(o, "description", json_string(doc));
    json_object_set_new(o, "type", json_string("object"));
    json_object_set_new(o, "additionalProperties", json_false());
    for (size_t i = 0; i < t->count; i++) {
        const pfx_key *k = &t->keys[i];
        json_t *p = json_object(), *s = row_schema(t, k);
        const bool kind_type = t->kind && !strcmp(k->name, "type");
        if (kind_type && doc) /* a kind's type row says what the kind is */
            json_object_set_new(p, "description", json_string(doc));
        else if (k->doc && k->doc[0])
            annotate(p, k, s, fragments);
        json_object_update(p, s);
        json_decref(s);
        json_object_set_new(props, k->name, p);
        if ((k->flags & PFX_KEY_REQUIRED) || kind_type)
            json_array_append_new(req, json_string(k->name));
    }
    json_object_set_new(o, "properties", props);
    if (json_array_size(req))
        json_object_set_new(o, "required", req);
    else
        json_decref(req);
    if (t->extra) {
        json_t *x = parse_fragment(t->extra);
        json_object_update(o, x);
        json_decref(x);
    }
    return o;
}

/* A family: an object whose `type` picks one of its kinds' tables. */
static json_t *family_schema(const pfx_schema_family *f) {
    json_t *o = json_object(), *props = json_object(), *type = json_object(), *one = json_array();
    json_object_set_new(o, "description", json_string(f->doc));
    json_object_set_new(o, "type", json_string("object"));
    json_t *req = json_array();
    json_array_append_new(req, json_string("type"));
    json_object_set_new(o, "required", req);
    json_object_set_new(type, "description", json_string(f->type_doc));
    json_object_set_new(type, "enum", names_array(f->kinds));
    json_object_set_new(props, "type", type);
    json_object_set_new(o, "properties", props);
    for (size_t i = 0; f->tables[i]; i++) {
        /* each kind says what it is, for the forms listed under a key */
        json_t *kind = ref(f->tables[i]->name);
        const char *doc = table_doc(f->tables[i]);
        if (doc)
            json_object_set_new(kind, "description", json_string(doc));
        json_array_append_new(one, kind);
    }
    json_object_set_new(o, "oneOf", one);
    return o;
}

/* `allow:` takes the ids of the warning rules: from the rule table, so the
 * schema lists exactly the rules an effect may acknowledge. */
static void allow_names(json_t *allow) {
    json_t *ids = json_array(), *names = json_object();
    for (size_t i = 0; i < pfx_rule_count; i++) {
        char id[16];
        if (pfx_rules[i].severity == PFX_SEV_WARNING)
            json_array_append_new(ids, json_string(pfx_rule_id(pfx_rules[i].rule, id, sizeof id)));
    }
    json_object_set_new(names, "enum", ids);
    json_object_set_new(allow, "propertyNames", names);
}

/* What an HDR colour accepts, for its error message. */
static const char *const hdr_colour_forms =
    "a colour: #rrggbb, #rrggbbaa, [r, g, b(, a)] with r, g, b in 0..1000 (above 1: brighter "
    "than white) and a in 0..1, or a CSS name such as 'orange'";

/* The colour fragments take the CSS colour names too: an enum from the
 * reader's table, so the schema and pfx accept the same names. Each form
 * carries the colour's error message (errorMessage, and
 * patternErrorMessage where a pattern is what failed): editors built on
 * vscode-json-languageservice or yaml-language-server report a failed
 * oneOf through its closest branch's own message, so a bad colour reads
 * as a colour error, not as a regular expression or 148 names. */
static void finish_colour(const char *name, json_t *fragment) {
    const bool hdr = !strcmp(name, "hdr_colour");
    if (!hdr && strcmp(name, "colour"))
        return;
    json_t *names = names_array(pfx_css_colour_names), *branch = json_object();
    json_object_set_new(branch, "description",
                        json_string("A CSS Color Module Level 4 named colour (red, orange, "
                                    "rebeccapurple): the sRGB colour of its #rrggbb, opaque."));
    json_object_set_new(branch, "type", json_string("string"));
    json_object_set_new(branch, "enum", names);
    json_array_append_new(json_object_get(fragment, "oneOf"), branch);
    char message[256];
    snprintf(message, sizeof message, "expected %s", hdr ? hdr_colour_forms : pfx_colour_forms);
    size_t i;
    json_array_foreach(json_object_get(fragment, "oneOf"), i, branch) {
        /* the type as a list: yaml-language-server rebuilds a mismatch of
         * one type from all the alternatives' types ("Incorrect type.
         * Expected string | array"), but reports a list's through
         * errorMessage */
        json_t *type = json_object_get(branch, "type");
        if (json_is_string(type))
            json_object_set_new(branch, "type", json_pack("[O]", type));
        json_object_set_new(branch, "errorMessage", json_string(message));
        if (json_object_get(branch, "pattern"))
            json_object_set_new(branch, "patternErrorMessage", json_string(message));
    }
}

char *pfx_schema_text(void) {
    json_t *root = json_object(), *defs = json_object();
    json_object_set_new(root, "$schema",
                        json_string("https://json-schema.org/draft/2020-12/schema"));
    json_object_set_new(root, "title", json_string(pfx_schema_title));
    json_object_set_new(root, "description", json_string(pfx_schema_top.doc));
    for (size_t i = 0; pfx_schema_fragments[i].name; i++) {
        json_t *fragment = parse_fragment(pfx_schema_fragments[i].json);
        finish_colour(pfx_schema_fragments[i].name, fragment);
        json_object_set_new(defs, pfx_schema_fragments[i].name, fragment);
    }
    /* what a property may refer to for its forms: the fragments and the
     * families (kept here, put in $defs in their own place below) */
    json_t *fragments = json_copy(defs);
    for (size_t i = 0; pfx_schema_families[i].name; i++)
        json_object_set_new(fragments, pfx_schema_families[i].name,
                            family_schema(&pfx_schema_families[i]));
    annotate_fragment(defs, fragments);
    json_t *top = table_schema(&pfx_schema_top, fragments);
    json_object_del(top, "description");
    allow_names(json_object_get(json_object_get(top, "properties"), "allow"));
    json_object_update(root, top);
    json_decref(top);
    for (size_t i = 0; pfx_schema_tables[i]; i++)
        json_object_set_new(defs, pfx_schema_tables[i]->name,
                            table_schema(pfx_schema_tables[i], fragments));
    for (size_t i = 0; pfx_schema_families[i].name; i++) {
        const pfx_schema_family *f = &pfx_schema_families[i];
        json_object_set(defs, f->name, json_object_get(fragments, f->name));
        for (size_t k = 0; f->tables[k]; k++)
            json_object_set_new(defs, f->tables[k]->name, table_schema(f->tables[k], fragments));
    }
    json_decref(fragments);
    json_object_set_new(root, "$defs", defs);
    char *text = json_dumps(root, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(15));
    json_decref(root);
    return text;
}
