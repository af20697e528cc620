# What `cmake --install build --prefix P` puts where (docs/install.md), in two components: the
# program (`runtime`: the plant Debian package) and the C++ API (`dev`: plant-dev).
#   P/bin/plant
#   P/lib/plant/plant-view-server.so   plant view's HTTP server, which only `plant view` loads; it
#                                  looks for it as ../lib/plant/ beside bin/ (cli/view_http_load.cpp)
#   P/share/plant/stdlib/          the standard library; bin/plant finds it as ../share/plant/stdlib
#                                  (lang/src/file_access.cpp), so these two paths go together
#   P/share/doc/plant/             README.md and docs/*.md
#   P/share/man/man1/plant.1       made from the commands' help (cli/CMakeLists.txt)
#   P/include/plant/               the public headers
#   P/lib/libplant_*.a             the libraries
#   P/lib/cmake/plant/             find_package(plant): the target plant::plant
include(CMakePackageConfigHelpers)

set(PLANT_INSTALL_STDLIBDIR share/plant/stdlib)
set(PLANT_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/plant)

install(TARGETS plant RUNTIME DESTINATION bin COMPONENT runtime)
install(TARGETS plant_view_server LIBRARY DESTINATION lib/plant COMPONENT runtime)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/stdlib/ DESTINATION ${PLANT_INSTALL_STDLIBDIR} COMPONENT runtime)
file(GLOB plant_docs CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/docs/*.md)
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${plant_docs} DESTINATION share/doc/plant COMPONENT runtime)
install(FILES ${PROJECT_BINARY_DIR}/plant.1 DESTINATION share/man/man1 COMPONENT runtime)

# The C++ API: plant::plant links the runtime (turtle, mesher, exporters) and the language.
set_target_properties(plant_common PROPERTIES EXPORT_NAME common)
set_target_properties(plant_lang PROPERTIES EXPORT_NAME lang)
set_target_properties(plant_physics PROPERTIES EXPORT_NAME physics)
set_target_properties(plant_runtime PROPERTIES EXPORT_NAME runtime)
add_library(plant_api INTERFACE)
target_link_libraries(plant_api INTERFACE plant_runtime plant_lang)
set_target_properties(plant_api PROPERTIES EXPORT_NAME plant)
add_library(plant::plant ALIAS plant_api)
install(TARGETS plant_common plant_lang plant_physics plant_runtime plant_api
        EXPORT plantTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
foreach(dir common/include/plant lang/include/plant runtime/include/plant runtime/physics/include/plant)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT dev)
endforeach()
install(EXPORT plantTargets NAMESPACE plant:: DESTINATION ${PLANT_INSTALL_CMAKEDIR} COMPONENT dev)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/plantConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/plantConfig.cmake
                              INSTALL_DESTINATION ${PLANT_INSTALL_CMAKEDIR}
                              PATH_VARS PLANT_INSTALL_STDLIBDIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/plantConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/plantConfig.cmake ${PROJECT_BINARY_DIR}/plantConfigVersion.cmake
        DESTINATION ${PLANT_INSTALL_CMAKEDIR} COMPONENT dev)
