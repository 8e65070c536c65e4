# Writes a C++ file with every api/*.json document as a string, looked up by file name
# through penumbra::api::embedded_document(name) (declared in api/embedded_documents.h).
# "@PENUMBRA_VERSION@" in a document becomes -DPENUMBRA_VERSION (the project's version).
if(NOT PENUMBRA_VERSION)
  message(FATAL_ERROR "embed_documents.cmake needs -DPENUMBRA_VERSION=<project version>")
endif()
file(GLOB docs ${DIR}/*.json)
set(body "#include \"api/embedded_documents.h\"\n#include <map>\n#include <string>\nnamespace penumbra::api {\nnamespace {\nconst std::map<std::string, std::string>& documents() {\n  static const std::map<std::string, std::string> m = {\n")
foreach(doc ${docs})
  get_filename_component(name ${doc} NAME)
  # Substituted in a copy, then read as hex so that every other byte passes through untouched.
  configure_file(${doc} ${OUT}.${name} @ONLY)
  file(READ ${OUT}.${name} hex HEX)
  file(REMOVE ${OUT}.${name})
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "\\\\x\\1" escaped "${hex}")
  string(LENGTH "${hex}" hexlen)
  math(EXPR len "${hexlen} / 2")
  string(APPEND body "    {\"${name}\", std::string(\"${escaped}\", ${len})},\n")
endforeach()
string(APPEND body "  };\n  return m;\n}\n}  // namespace\nconst std::string* embedded_document(const std::string& name) {\n  auto it = documents().find(name);\n  return it == documents().end() ? nullptr : &it->second;\n}\n}  // namespace penumbra::api\n")
file(WRITE ${OUT} "${body}")
