# CTest python_install: `cmake --install` of the Python module into a fresh prefix, then `import hwbounds` in a
# clean environment whose only path to it is that prefix's module folder (not the build tree).
# Arguments: BUILD_DIR, PREFIX, MODULE_DIR (relative to PREFIX), PYTHON.
file(REMOVE_RECURSE ${PREFIX})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${PREFIX} --component python
                RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "cmake --install failed (${status}):\n${out}")
endif()
set(module_path ${PREFIX}/${MODULE_DIR})
file(GLOB installed ${module_path}/hwbounds*.so)
if(NOT installed)
  message(FATAL_ERROR "no hwbounds*.so in ${module_path} after the install:\n${out}")
endif()
# env -i: no inherited PYTHONPATH or LD_LIBRARY_PATH; run from the prefix, away from build/python.
set(check "import hwbounds, os; f = os.path.realpath(hwbounds.__file__); \
assert f.startswith(os.path.realpath('${module_path}')), f; \
assert callable(hwbounds.bounds) and callable(hwbounds.simulate); print('imported', f)")
execute_process(COMMAND env -i PATH=/usr/bin:/bin PYTHONPATH=${module_path} ${PYTHON} -c "${check}"
                WORKING_DIRECTORY ${PREFIX} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "import of the installed module failed (${status}):\n${out}")
endif()
message(STATUS "${out}")
file(REMOVE_RECURSE ${PREFIX})
