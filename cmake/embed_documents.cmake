# Writes a C++ file with every api/*.json document as a string, looked up by file name
# through penumbra::api::embedded_document(name) (declared in api/embedded_documents.h).
file(GLOB docs ${DIR}/*.json)
set(body "#include \"api/embedded_documents.h\"\n#include <map>\n#include <string>\nnamespace penumbra::api {\nnamespace {\nconst std::map<std::string, std::string>& documents() {\n  static const std::map<std::string, std::string> m = {\n")
foreach(doc ${docs})
  get_filename_component(name ${doc} NAME)
  file(READ ${doc} hex HEX)
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "\\\\x\\1" escaped "${hex}")
  string(LENGTH "${hex}" hexlen)
  math(EXPR len "${hexlen} / 2")
  string(APPEND body "    {\"${name}\", std::string(\"${escaped}\", ${len})},\n")
endforeach()
string(APPEND body "  };\n  return m;\n}\n}  // namespace\nconst std::string* embedded_document(const std::string& name) {\n  auto it = documents().find(name);\n  return it == documents().end() ? nullptr : &it->second;\n}\n}  // namespace penumbra::api\n")
file(WRITE ${OUT} "${body}")
