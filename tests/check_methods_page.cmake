# Fails when docs/methods.md differs from `nystrom methods --markdown` (the page is generated from the
# catalog). Run by CTest as methods_page_is_current: cmake -DTOOL=<nystrom> -DPAGE=<docs/methods.md> -P this.
execute_process(COMMAND ${TOOL} methods --markdown OUTPUT_VARIABLE generated RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "`nystrom methods --markdown` failed with status ${rc}")
endif()
file(READ ${PAGE} committed)
if(NOT generated STREQUAL committed)
  message(FATAL_ERROR "${PAGE} is stale: regenerate it with `nystrom methods --markdown > docs/methods.md`")
endif()
