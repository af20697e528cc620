# Writes the man page plant.1 from the program's own help (plant help --man), at build time
# (cli/CMakeLists.txt): PLANT is the program, OUT the page.
execute_process(COMMAND "${PLANT}" help --man OUTPUT_FILE "${OUT}.tmp" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  file(REMOVE "${OUT}.tmp")
  message(FATAL_ERROR "plant help --man failed (${rc})")
endif()
file(RENAME "${OUT}.tmp" "${OUT}")
