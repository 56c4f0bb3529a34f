/* `pfx schema`: the JSON Schema (2020-12) of the effect format, written from
 * the key tables. Each row becomes a property (its type, range, default and
 * description); each table a definition; each kinded family (forces,
 * shapes, deflectors, regions) a `type`-discriminated choice of its kinds'
 * tables. Syntaxes that code reads (a random value, a colour, a gradient)
 * are fragments beside their readers' rows. JSON goes through jansson. */
#include "compile/schema.h"

#include <jansson.h>
#include <math.h>
#include <string.h>

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

/* A table as an object schema: its rows as properties, its extra rules. */
static json_t *table_schema(const pfx_key_table *t) {
    json_t *o = json_object(), *props = json_object(), *req = json_array();
    const char *doc = table_doc(t);
    if (doc)
        json_object_set_new(o, "description", json_string(doc));
    json_object_set_new(o, "type", json_string("object"));
    json_object_set_new(o, "additionalProperties", json_false());
    for (size_t i = 0; i < t->count; i++) {
        const pfx_key *k = &t->keys[i];
        json_t *p = json_object(), *s = row_schema(t, k);
        /* a kind's type row says what the kind is */
        const char *rdoc = t->kind && !strcmp(k->name, "type") && doc ? doc : k->doc;
        if (rdoc && rdoc[0])
            json_object_set_new(p, "description", json_string(rdoc));
        json_object_update(p, s);
        json_decref(s);
        json_object_set_new(props, k->name, p);
        if ((k->flags & PFX_KEY_REQUIRED) || (t->kind && !strcmp(k->name, "type")))
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
    for (size_t i = 0; f->tables[i]; i++)
        json_array_append_new(one, ref(f->tables[i]->name));
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

/* The colour fragments take the CSS colour names too: an enum from the
 * reader's table, so the schema and pfx accept the same names. */
static void add_colour_names(const char *name, json_t *fragment) {
    if (strcmp(name, "colour") && strcmp(name, "hdr_colour"))
        return;
    json_t *names = names_array(pfx_css_colour_names), *branch = json_object();
    json_object_set_new(branch, "description",
                        json_string("A CSS Color Module Level 4 named colour (red, orange, "
                                    "rebeccapurple): the sRGB colour of its #rrggbb, opaque."));
    json_object_set_new(branch, "type", json_string("string"));
    json_object_set_new(branch, "enum", names);
    json_array_append_new(json_object_get(fragment, "oneOf"), branch);
}

char *pfx_schema_text(void) {
    json_t *root = json_object(), *defs = json_object();
    json_object_set_new(root, "$schema",
                        json_string("https://json-schema.org/draft/2020-12/schema"));
    json_object_set_new(root, "title", json_string(pfx_schema_title));
    json_object_set_new(root, "description", json_string(pfx_schema_top.doc));
    json_t *top = table_schema(&pfx_schema_top);
    json_object_del(top, "description");
    allow_names(json_object_get(json_object_get(top, "properties"), "allow"));
    json_object_update(root, top);
    json_decref(top);
    for (size_t i = 0; pfx_schema_fragments[i].name; i++) {
        json_t *fragment = parse_fragment(pfx_schema_fragments[i].json);
        add_colour_names(pfx_schema_fragments[i].name, fragment);
        json_object_set_new(defs, pfx_schema_fragments[i].name, fragment);
    }
    for (size_t i = 0; pfx_schema_tables[i]; i++)
        json_object_set_new(defs, pfx_schema_tables[i]->name, table_schema(pfx_schema_tables[i]));
    for (size_t i = 0; pfx_schema_families[i].name; i++) {
        const pfx_schema_family *f = &pfx_schema_families[i];
        json_object_set_new(defs, f->name, family_schema(f));
        for (size_t k = 0; f->tables[k]; k++)
            json_object_set_new(defs, f->tables[k]->name, table_schema(f->tables[k]));
    }
    json_object_set_new(root, "$defs", defs);
    char *text = json_dumps(root, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(15));
    json_decref(root);
    return text;
}
