# The installed package (docs/package.md): `make install PREFIX=...` puts
# the mechopt binary, shared libraries mechopt::mech and mechopt::opt with
# their headers, a CMake package (find_package(mechopt 0.2)), a pkg-config
# file and the Python module under PREFIX.
#
# The shared libraries are linked from the objects this build already has
# (every object is PIC): mech's whole, then libopt's parts and the built-in
# problems whole in opt, so that the problems register themselves when the
# library loads. SUNDIALS, NLopt, Ipopt, SQLite and MPI stay private; Eigen,
# nlohmann_json and yaml-cpp appear in the public headers and are found by
# the package's config file.
set(CMAKE_INSTALL_LIBDIR lib)  # PREFIX/lib, as mechopt.pc finds it from its own directory
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# Built for AVX2 or not, and Eigen's alignment with it: 32 bytes with AVX,
# 16 without. The alignment is part of the ABI (a vector the library
# allocates, the caller frees), so consumers compile with the library's.
if(MECHOPT_USE_AVX2 AND NOT MECHOPT_AVX2 STREQUAL "OFF")
  set(MECHOPT_PACKAGE_AVX2 ON)
  set(MECHOPT_EIGEN_ALIGN 32)
else()
  set(MECHOPT_PACKAGE_AVX2 OFF)
  set(MECHOPT_EIGEN_ALIGN 16)
endif()

add_library(mechopt_mech SHARED ${CMAKE_SOURCE_DIR}/cmake/cpu_check.cpp)
target_link_libraries(mechopt_mech PRIVATE -Wl,--whole-archive $<TARGET_FILE:mech> -Wl,--no-whole-archive mech)
target_include_directories(mechopt_mech INTERFACE $<BUILD_INTERFACE:${CMAKE_SOURCE_DIR}/libmech/include>
                                                  $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
target_link_libraries(mechopt_mech INTERFACE Eigen3::Eigen)
target_compile_definitions(mechopt_mech INTERFACE $<INSTALL_INTERFACE:EIGEN_MAX_ALIGN_BYTES=${MECHOPT_EIGEN_ALIGN}>)
set(MECHOPT_PARTS opt_studies opt_doe opt_report opt_config opt_drivers opt_core opt_units)
set(MECHOPT_PART_FILES)
foreach(part ${MECHOPT_PARTS})
  list(APPEND MECHOPT_PART_FILES $<TARGET_FILE:${part}>)
endforeach()
add_library(mechopt_opt SHARED $<TARGET_OBJECTS:problems>)
target_link_libraries(mechopt_opt PRIVATE -Wl,--whole-archive ${MECHOPT_PART_FILES} -Wl,--no-whole-archive opt)
target_link_libraries(mechopt_opt PUBLIC mechopt_mech)
target_include_directories(mechopt_opt INTERFACE $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
target_link_libraries(mechopt_opt INTERFACE $<INSTALL_INTERFACE:nlohmann_json::nlohmann_json>
                                            $<INSTALL_INTERFACE:yaml-cpp>)
set_target_properties(mechopt_mech PROPERTIES EXPORT_NAME mech VERSION ${PROJECT_VERSION} SOVERSION
                      ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
set_target_properties(mechopt_opt PROPERTIES EXPORT_NAME opt VERSION ${PROJECT_VERSION} SOVERSION
                      ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR}
                      INSTALL_RPATH "$ORIGIN")
add_dependencies(mechopt_opt ${MECHOPT_PARTS})

install(TARGETS mechopt_mech mechopt_opt EXPORT mechoptTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(DIRECTORY ${CMAKE_SOURCE_DIR}/libmech/include/ ${CMAKE_SOURCE_DIR}/libopt/include/
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS mechopt RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(EXPORT mechoptTargets NAMESPACE mechopt:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mechopt)
configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/mechoptConfig.cmake.in
                              ${CMAKE_BINARY_DIR}/package/mechoptConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mechopt)
write_basic_package_version_file(${CMAKE_BINARY_DIR}/package/mechoptConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/package/mechoptConfig.cmake ${CMAKE_BINARY_DIR}/package/mechoptConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mechopt)
configure_file(${CMAKE_SOURCE_DIR}/cmake/mechopt.pc.in ${CMAKE_BINARY_DIR}/package/mechopt.pc @ONLY)
install(FILES ${CMAKE_BINARY_DIR}/package/mechopt.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
