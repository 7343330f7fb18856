# Fails when the committed generated documents differ from what the current
# build generates: docs/scenario-reference.md (domel docs) and
# docs/domel.schema.json (domel schema). Fix: regenerate with the commands
# printed below and commit.
foreach(pair "docs;scenario-reference.md" "schema;domel.schema.json")
  list(GET pair 0 cmd)
  list(GET pair 1 file)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env --unset=DOMEL_PLUGIN_PATH ${DOMEL} ${cmd}
                  OUTPUT_VARIABLE generated RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "domel ${cmd} failed (${rc})")
  endif()
  file(READ ${SRC}/docs/${file} committed)
  if(NOT generated STREQUAL committed)
    message(FATAL_ERROR "docs/${file} is out of date: run `build/bin/domel ${cmd} --out docs/${file}` and commit it")
  endif()
endforeach()
