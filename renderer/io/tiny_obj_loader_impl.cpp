// tinyobjloader's implementation, from the single header Debian's libtinyobjloader-dev ships.
// It is compiled here instead of linking libtinyobjloader.so so that the sanitizer and libFuzzer
// builds (scripts/sanitize.sh, scripts/fuzz.sh) instrument the parser that reads untrusted OBJ
// files too: a bug inside it is then reported, not silently stepped over. Only
// renderer/io/obj_reader.cpp uses it, on bytes it has screened (see there).
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>
