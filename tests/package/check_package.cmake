# Builds the consumer project (tests/package/consumer) both ways for one linkage, static or shared:
#   1. add_subdirectory of this source tree, which compiles the library (options off: a subproject gets
#      no CLI, tests or oracle) and the consumer; run the consumer;
#   2. `cmake --install` of that same build into a fresh prefix, then a second consumer build that finds
#      the installed package with find_package(exactgeo CONFIG) and compiles only the consumer; run it.
# Installing the subproject build is what makes this affordable: the library is compiled once per linkage.
# Kept between runs, the work folder makes later runs recompile only what changed.
#
#   cmake -DSOURCE_DIR=... -DWORK_DIR=... -DSHARED=ON|OFF -DGENERATOR=Ninja -DCXX_COMPILER=... -P check_package.cmake
foreach(variable SOURCE_DIR WORK_DIR SHARED GENERATOR CXX_COMPILER)
  if(NOT DEFINED ${variable})
    message(FATAL_ERROR "check_package.cmake needs -D${variable}=...")
  endif()
endforeach()
set(consumer_dir ${SOURCE_DIR}/tests/package/consumer)
set(prefix ${WORK_DIR}/prefix)
# Library-only and quick to compile; a Debug build also has the engine's assertions on.
set(common_options -G ${GENERATOR} -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_BUILD_TYPE=Debug
                   -DBUILD_SHARED_LIBS=${SHARED})

function(run)
  message(STATUS "check_package: ${ARGN}")
  execute_process(COMMAND ${ARGN} COMMAND_ERROR_IS_FATAL ANY)
endfunction()

# A fresh configuration each time (the cache of an earlier run must not hide a problem), same object files.
foreach(build subdirectory installed)
  file(REMOVE ${WORK_DIR}/${build}/CMakeCache.txt)
endforeach()
file(REMOVE_RECURSE ${prefix})

run(${CMAKE_COMMAND} -S ${consumer_dir} -B ${WORK_DIR}/subdirectory ${common_options}
    -DEXACTGEO_SOURCE_DIR=${SOURCE_DIR})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/subdirectory --parallel 2)
run(${WORK_DIR}/subdirectory/consumer)

run(${CMAKE_COMMAND} --install ${WORK_DIR}/subdirectory --prefix ${prefix})
# The license travels with the package.
if(NOT EXISTS ${prefix}/share/doc/exactgeo/LICENSE)
  message(FATAL_ERROR "check_package: the installed package has no share/doc/exactgeo/LICENSE")
endif()
run(${CMAKE_COMMAND} -S ${consumer_dir} -B ${WORK_DIR}/installed ${common_options} -DCMAKE_PREFIX_PATH=${prefix})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/installed --parallel 2)
run(${WORK_DIR}/installed/consumer)
