# Writes OUT, a C file holding each page file of src/serve/page as a byte
# array and a pfx_page_asset (src/serve/page_assets.h). Run by CMake at
# build time (cmake -P) whenever a page file changes: no node, no xxd.
set(assets "index.html|pfx_page_index_html|text/html"
           "app.js|pfx_page_app_js|text/javascript"
           "style.css|pfx_page_style_css|text/css")
set(code "/* Generated from src/serve/page by cmake/embed_page.cmake; do not edit. */\n#include \"serve/page_assets.h\"\n")
foreach(row IN LISTS assets)
  string(REPLACE "|" ";" row "${row}")
  list(GET row 0 file)
  list(GET row 1 name)
  list(GET row 2 type)
  file(READ "${PAGE_DIR}/${file}" hex HEX)
  string(LENGTH "${hex}" n)
  math(EXPR bytes "${n} / 2")
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," hex "${hex}")
  string(REGEX REPLACE "((0x..,){16})" "\\1\n" hex "${hex}")
  string(APPEND code "static const unsigned char ${name}_bytes[] = {\n${hex}0};\n")
  string(APPEND code "const pfx_page_asset ${name} = {${name}_bytes, ${bytes}, \"${type}; charset=utf-8\"};\n")
endforeach()
file(WRITE "${OUT}.tmp" "${code}")
file(RENAME "${OUT}.tmp" "${OUT}")
