# Turns a text file into a C++ source defining `const char* const domel::platform::<NAME>`.
# -DIN=<file> -DOUT=<cpp> [-DNAME=<identifier>, default kScenarioSchemaText]
if(NOT NAME)
  set(NAME kScenarioSchemaText)
endif()
file(READ ${IN} content)
file(WRITE ${OUT} "// GENERATED from ${IN} - edit that file.\n")
file(APPEND ${OUT} "namespace domel::platform { extern const char* const ${NAME};\n")
file(APPEND ${OUT} "const char* const ${NAME} = R\"domeltext(${content})domeltext\"; }\n")
