# Turns scenario.schema.json into a C++ source defining domel::platform::kScenarioSchemaText.
file(READ ${IN} content)
file(WRITE ${OUT} "// GENERATED from platform/scenario/scenario.schema.json - edit that file.\n")
file(APPEND ${OUT} "namespace domel::platform { extern const char* const kScenarioSchemaText;\n")
file(APPEND ${OUT} "const char* const kScenarioSchemaText = R\"domelschema(${content})domelschema\"; }\n")
