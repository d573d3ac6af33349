# ctest package.consumer (cmake -P): installs the build BUILD under WORK/prefix
# as `make install PREFIX=...` does, builds examples/consumer against it with
# find_package(mechopt 0.2), runs it and the installed binary, and imports
# the installed Python module where the build has one.
file(REMOVE_RECURSE ${WORK})
function(step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE r OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(r)
    message(FATAL_ERROR "${what} failed (${r}):\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()
step("install" ${CMAKE_COMMAND} --install ${BUILD} --prefix ${WORK}/prefix)
step("configuring the consumer" ${CMAKE_COMMAND} -S ${SOURCE}/examples/consumer -B ${WORK}/build
     -DCMAKE_PREFIX_PATH=${WORK}/prefix -DCMAKE_BUILD_TYPE=Release)
step("building the consumer" ${CMAKE_COMMAND} --build ${WORK}/build)
step("running the consumer" ${WORK}/build/consumer)
message("${out}")
# 41.752 deg: the closed form at a = 0.1, b = 0.45, c = 0.35, d = 0.4 m,
# acos((b^2 + c^2 - (d - a)^2) / 2bc), computed apart (docs/package.md).
foreach(expected "consumer_four_bar min_transmission_angle 41.752" "recuperative_drive mean_kinetic_energy"
                 "registered 2 of")
  string(FIND "${out}" "${expected}" at)
  if(at LESS 0)
    message(FATAL_ERROR "the consumer's output lacks '${expected}'")
  endif()
endforeach()
step("the installed binary" ${WORK}/prefix/bin/mechopt --version)
if(NOT out MATCHES "mechopt ${VERSION}")
  message(FATAL_ERROR "the installed binary says '${out}', not mechopt ${VERSION}")
endif()
file(GLOB module ${WORK}/prefix/lib/python3*/dist-packages/mechopt/__init__.py)
if(PYTHON AND module)
  get_filename_component(dir ${module} DIRECTORY)
  get_filename_component(dir ${dir} DIRECTORY)
  step("importing the installed module" ${CMAKE_COMMAND} -E env PYTHONPATH=${dir} ${PYTHON} -c
       "import mechopt; print(mechopt.__version__, len(mechopt.problems()))")
  message("python: ${out}")
elseif(PYTHON)
  message(FATAL_ERROR "the Python module was not installed under ${WORK}/prefix/lib")
endif()
