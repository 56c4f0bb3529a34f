/* The escaping of base/json_text.h: UTF-8 checked as jansson checks it
 * (no overlong forms, no surrogates, nothing past U+10FFFF), base64 from
 * RFC 4648. It only converts; it neither reads nor writes files. */
#include "base/json_text.h"

#include <stdlib.h>
#include <string.h>

#define BASE64_SUFFIX "_base64"

/* The length of the UTF-8 character at p (n bytes left), or 0 when the
 * bytes there are not one. */
static size_t utf8_char(const unsigned char *p, size_t n) {
    unsigned c = p[0];
    size_t len;
    unsigned min;
    if (c < 0x80)
        return 1;
    if (c >= 0xc2 && c <= 0xdf)
        len = 2, min = 0x80;
    else if (c >= 0xe0 && c <= 0xef)
        len = 3, min = 0x800;
    else if (c >= 0xf0 && c <= 0xf4)
        len = 4, min = 0x10000;
    else
        return 0;
    if (n < len)
        return 0;
    unsigned v = c & (0x7f >> len);
    for (size_t i = 1; i < len; i++) {
        if ((p[i] & 0xc0) != 0x80)
            return 0;
        v = (v << 6) | (p[i] & 0x3f);
    }
    if (v < min || v > 0x10ffff || (v >= 0xd800 && v <= 0xdfff))
        return 0;
    return len;
}

static bool is_utf8(const char *s, size_t n) {
    const unsigned char *p = (const unsigned char *)s;
    for (size_t i = 0; i < n;) {
        size_t k = utf8_char(p + i, n - i);
        if (!k)
            return false;
        i += k;
    }
    return true;
}

/* s with each byte outside a character as U+FFFD (EF BF BD); malloc'd. */
static char *replaced(const char *s, size_t n) {
    char *out = malloc(3 * n + 1), *o = out;
    const unsigned char *p = (const unsigned char *)s;
    if (!out)
        return NULL;
    for (size_t i = 0; i < n;) {
        size_t k = utf8_char(p + i, n - i);
        if (k) {
            memcpy(o, p + i, k);
            o += k, i += k;
        } else {
            memcpy(o, "\xef\xbf\xbd", 3);
            o += 3, i++;
        }
    }
    *o = 0;
    return out;
}

static const char b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

static char *base64(const unsigned char *p, size_t n) {
    char *out = malloc(4 * ((n + 2) / 3) + 1), *o = out;
    if (!out)
        return NULL;
    for (size_t i = 0; i < n; i += 3) {
        unsigned v = (unsigned)p[i] << 16 | (i + 1 < n ? (unsigned)p[i + 1] << 8 : 0) |
                     (i + 2 < n ? p[i + 2] : 0);
        *o++ = b64[v >> 18 & 63];
        *o++ = b64[v >> 12 & 63];
        *o++ = i + 1 < n ? b64[v >> 6 & 63] : '=';
        *o++ = i + 2 < n ? b64[v & 63] : '=';
    }
    *o = 0;
    return out;
}

/* The bytes of base64 text t (malloc'd, NUL-terminated, *n of them), or
 * NULL when t is not base64 or decodes to a NUL byte (no file name has
 * one). */
static char *unbase64(const char *t, size_t *n) {
    size_t len = strlen(t);
    if (len % 4)
        return NULL;
    char *out = malloc(len / 4 * 3 + 1);
    size_t k = 0;
    for (size_t i = 0; out && i < len; i += 4) {
        unsigned v = 0;
        int pad = 0;
        for (int j = 0; j < 4; j++) {
            const char *c = t[i + j] == '=' ? NULL : strchr(b64, t[i + j]);
            if (t[i + j] == '=' && i + 4 == len && j >= 2)
                pad++;
            else if (!c || !t[i + j] || pad) {
                free(out);
                return NULL;
            }
            v = v << 6 | (c ? (unsigned)(c - b64) : 0);
        }
        out[k++] = (char)(v >> 16);
        if (pad < 2)
            out[k++] = (char)(v >> 8 & 255);
        if (pad < 1)
            out[k++] = (char)(v & 255);
    }
    if (out && memchr(out, 0, k)) {
        free(out);
        return NULL;
    }
    if (out)
        out[k] = 0;
    *n = k;
    return out;
}

json_t *pfx_json_bytes(const char *s) { return json_string_nocheck(s); }

/* A copy of string v that jansson can dump (U+FFFD where needed). */
static json_t *valid_string(const json_t *v) {
    const char *s = json_string_value(v);
    size_t n = json_string_length(v);
    if (is_utf8(s, n))
        return json_stringn(s, n);
    char *r = replaced(s, n);
    json_t *j = r ? json_string(r) : NULL;
    free(r);
    return j;
}

json_t *pfx_json_escaped(const json_t *v) {
    if (json_is_string(v))
        return valid_string(v);
    if (json_is_array(v)) {
        json_t *a = json_array();
        size_t i;
        const json_t *x;
        json_array_foreach(v, i, x) {
            if (!a || json_array_append_new(a, pfx_json_escaped(x))) {
                json_decref(a);
                return NULL;
            }
        }
        return a;
    }
    if (!json_is_object(v))
        return json_deep_copy(v);
    json_t *o = json_object();
    const char *key;
    json_t *x;
    json_object_foreach((json_t *)v, key, x) {
        bool ok = o != NULL;
        char *k = is_utf8(key, strlen(key)) ? NULL : replaced(key, strlen(key));
        ok = ok && json_object_set_new(o, k ? k : key, pfx_json_escaped(x)) == 0;
        free(k);
        if (ok && json_is_string(x) && !is_utf8(json_string_value(x), json_string_length(x))) {
            /* The exact bytes beside the readable form. */
            size_t n = strlen(key) + sizeof BASE64_SUFFIX;
            char *name = malloc(n),
                 *enc = base64((const unsigned char *)json_string_value(x), json_string_length(x));
            char *kname = name ? replaced(key, strlen(key)) : NULL;
            if (kname) {
                snprintf(name, n, "%s" BASE64_SUFFIX, kname);
                ok = enc && json_object_set_new(o, name, json_string(enc)) == 0;
            } else {
                ok = false;
            }
            free(kname);
            free(name);
            free(enc);
        }
        if (!ok) {
            json_decref(o);
            return NULL;
        }
    }
    return o;
}

void pfx_json_unescape(json_t *v) {
    if (json_is_array(v)) {
        size_t i;
        json_t *x;
        json_array_foreach(v, i, x) pfx_json_unescape(x);
        return;
    }
    if (!json_is_object(v))
        return;
    const char *key;
    json_t *x;
    void *tmp;
    json_object_foreach_safe(v, tmp, key, x) {
        size_t len = strlen(key), slen = strlen(BASE64_SUFFIX);
        if (json_is_object(x) || json_is_array(x)) {
            pfx_json_unescape(x);
            continue;
        }
        if (len <= slen || strcmp(key + len - slen, BASE64_SUFFIX) || !json_is_string(x))
            continue;
        char base[1024];
        if (len - slen >= sizeof base)
            continue;
        memcpy(base, key, len - slen);
        base[len - slen] = 0;
        size_t n;
        char *bytes =
            json_is_string(json_object_get(v, base)) ? unbase64(json_string_value(x), &n) : NULL;
        if (!bytes)
            continue;
        json_object_set_new(v, base, json_stringn_nocheck(bytes, n));
        free(bytes);
        json_object_del(v, key);
    }
}
