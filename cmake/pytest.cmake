# One CTest test per pytest file: saresgs_pytest(NAME FILE WORKING_DIRECTORY), run with the
# caller's ${Python3_EXECUTABLE}. Each file gets a temporary folder of its own under
# BUILD/pytest: pytest sessions run side by side (ctest --parallel) otherwise share
# /tmp/pytest-of-USER and prune each other's folders.
function(saresgs_pytest name file workdir)
  file(MAKE_DIRECTORY ${CMAKE_BINARY_DIR}/pytest)
  add_test(NAME ${name} COMMAND ${Python3_EXECUTABLE} -m pytest -q -p no:cacheprovider
                                --basetemp=${CMAKE_BINARY_DIR}/pytest/${name} ${file}
           WORKING_DIRECTORY ${workdir})
endfunction()
