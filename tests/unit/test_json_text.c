/* base/json_text.h: UTF-8 passes as it is; other bytes become U+FFFD
 * with the exact bytes in "<key>_base64" (RFC 4648's own test vectors),
 * and a dump read back and unescaped gives the bytes again. */
#include <jansson.h>

#include "base/json_text.h"
#include "test.h"

/* obj {"path": s} escaped and dumped compactly; malloc'd. */
static char *dumped(const char *s) {
    json_t *o = json_pack("{s:o}", "path", pfx_json_bytes(s));
    json_t *e = pfx_json_escaped(o);
    char *text = e ? json_dumps(e, JSON_COMPACT | JSON_PRESERVE_ORDER) : NULL;
    json_decref(e);
    json_decref(o);
    return text;
}

static void test_utf8_is_kept(void) {
    char *t = dumped("fire/caf\xc3\xa9 \xf0\x9f\x94\xa5.yaml");
    CHECK(t && !strcmp(t, "{\"path\":\"fire/caf\xc3\xa9 \xf0\x9f\x94\xa5.yaml\"}"));
    free(t);
}

static void test_other_bytes(void) {
    /* "f\xe9o": 'f', 0x66 0xe9 0x6f -> base64 "Zulv"; "\xff" alone -> "/w==". */
    char *t = dumped("f\xe9o");
    CHECK(t && !strcmp(t, "{\"path\":\"f\xef\xbf\xbdo\",\"path_base64\":\"Zulv\"}"));
    free(t);
    t = dumped("\xff");
    CHECK(t && !strcmp(t, "{\"path\":\"\xef\xbf\xbd\",\"path_base64\":\"/w==\"}"));
    free(t);
    /* An overlong '/' (C0 AF) and a UTF-16 surrogate (ED A0 80) are not
     * UTF-8 either: one U+FFFD a byte. */
    t = dumped("\xc0\xaf\xed\xa0\x80");
    CHECK(t && strstr(t, "\"path_base64\":\"wK/toIA=\""));
    free(t);
}

static void test_round_trip(void) {
    char all[256];
    for (int i = 1; i < 256; i++)
        all[i - 1] = (char)i;
    all[255] = 0;
    char *t = dumped(all);
    json_error_t err;
    json_t *back = t ? json_loads(t, 0, &err) : NULL;
    CHECK(back != NULL);
    pfx_json_unescape(back);
    json_t *p = json_object_get(back, "path");
    CHECK(json_string_length(p) == 255 && !memcmp(json_string_value(p), all, 255));
    CHECK(json_object_get(back, "path_base64") == NULL);
    json_decref(back);
    free(t);
}

int main(void) {
    RUN(test_utf8_is_kept);
    RUN(test_other_bytes);
    RUN(test_round_trip);
    return TEST_EXIT();
}
