/* The preview page's files (src/serve/page/), embedded in the binary at
 * build time by cmake/embed_page.cmake: the page works offline and
 * nothing is served from the disk. */
#ifndef PFX_SERVE_PAGE_ASSETS_H
#define PFX_SERVE_PAGE_ASSETS_H

#include <stddef.h>

typedef struct pfx_page_asset {
    const unsigned char *bytes;
    size_t len;
    const char *type; /* the Content-Type */
} pfx_page_asset;

extern const pfx_page_asset pfx_page_index_html, pfx_page_app_js, pfx_page_style_css;

#endif
