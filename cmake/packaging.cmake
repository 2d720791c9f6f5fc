# libgroundplan (shared, for C++ callers), install rules and the Debian package (CPack).
# Debian's multiarch library folder, also for a /usr/local install (GNUInstallDirs picks it only for /usr).
if(CMAKE_LIBRARY_ARCHITECTURE AND NOT DEFINED CMAKE_INSTALL_LIBDIR)
  set(CMAKE_INSTALL_LIBDIR "lib/${CMAKE_LIBRARY_ARCHITECTURE}" CACHE PATH "Object code libraries (LIBDIR)")
endif()
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# One shared library holding core + gis; the static parts stay for the plugin and the CLI.
add_library(libgroundplan SHARED ${CMAKE_SOURCE_DIR}/packaging/libgroundplan.cpp $<TARGET_OBJECTS:groundplan_core>
                                  $<TARGET_OBJECTS:groundplan_gis> $<TARGET_OBJECTS:groundplan_geosref>)
target_link_libraries(libgroundplan PRIVATE groundplan_flags PkgConfig::MPFR TBB::tbb PROJ::proj EXPAT::EXPAT
                                            GEOS::geos_c GDAL::GDAL groundplan_geographiclib PkgConfig::GMPXX simdjson::simdjson
                                            pugixml::static)
target_link_libraries(libgroundplan PRIVATE ${CMAKE_DL_LIBS})   # the CUDA module is loaded, not linked (gpu/)
target_include_directories(libgroundplan INTERFACE $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
set_target_properties(libgroundplan PROPERTIES OUTPUT_NAME groundplan VERSION ${PROJECT_VERSION}
                                               SOVERSION ${PROJECT_VERSION_MAJOR}
                                               LIBRARY_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/lib)

# GDAL finds plugins without GDAL_DRIVER_PATH only in the folder compiled into it: Debian's GDAL uses
# /usr/lib/<arch>/gdalplugins, whatever our install prefix.
if(CMAKE_LIBRARY_ARCHITECTURE)
  set(default_plugin_dir "/usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/gdalplugins")
else()
  set(default_plugin_dir "${CMAKE_INSTALL_LIBDIR}/gdalplugins")
endif()
set(GROUNDPLAN_GDAL_PLUGIN_INSTALL_DIR "${default_plugin_dir}" CACHE STRING
    "Where the OGR plugin is installed (GDAL's plugin folder)")

install(TARGETS groundplan RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
install(TARGETS ogr_GroundPlan LIBRARY DESTINATION ${GROUNDPLAN_GDAL_PLUGIN_INSTALL_DIR} COMPONENT runtime)
# The CUDA raster backend's module, beside libgroundplan in the library folder where dlopen finds it by name.
if(TARGET groundplan_cuda)
  install(TARGETS groundplan_cuda LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime NAMELINK_SKIP)
endif()
install(TARGETS libgroundplan EXPORT groundplanTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime NAMELINK_COMPONENT runtime)
install(DIRECTORY ${CMAKE_SOURCE_DIR}/core/include/groundplan ${CMAKE_SOURCE_DIR}/gis/include/groundplan
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT runtime FILES_MATCHING PATTERN "*.h")
# The QGIS plugin (qgis/groundplan_provider): QGIS looks for Python plugins in its own
# pkgDataPath()/python/plugins, compiled into it (Debian: /usr/share/qgis/python/plugins, beside its processing
# and db_manager), in the user's profile and in QGIS_PLUGINPATH; the first is the one an install may write,
# whatever our prefix (as for GDAL's plugin folder above). QGIS lists it under Plugins > Manage and Install
# Plugins; enabling it there adds the algorithm to the Processing toolbox.
set(GROUNDPLAN_QGIS_PLUGIN_INSTALL_DIR "/usr/share/qgis/python/plugins" CACHE STRING
    "Where the QGIS Processing plugin is installed (QGIS's plugin folder; relative paths are under CMAKE_INSTALL_PREFIX)")
install(DIRECTORY ${CMAKE_SOURCE_DIR}/qgis/groundplan_provider DESTINATION ${GROUNDPLAN_QGIS_PLUGIN_INSTALL_DIR}
        COMPONENT runtime FILES_MATCHING PATTERN "*.py" PATTERN "metadata.txt" PATTERN "__pycache__" EXCLUDE)
install(FILES ${CMAKE_SOURCE_DIR}/packaging/groundplan.1 DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 COMPONENT runtime)
install(FILES ${CMAKE_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT runtime)

install(EXPORT groundplanTargets NAMESPACE groundplan:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/groundplan
        COMPONENT runtime)
configure_package_config_file(${CMAKE_SOURCE_DIR}/packaging/groundplanConfig.cmake.in
                              ${CMAKE_BINARY_DIR}/groundplanConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/groundplan)
write_basic_package_version_file(${CMAKE_BINARY_DIR}/groundplanConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/groundplanConfig.cmake ${CMAKE_BINARY_DIR}/groundplanConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/groundplan COMPONENT runtime)
configure_file(${CMAKE_SOURCE_DIR}/packaging/groundplan.pc.in ${CMAKE_BINARY_DIR}/groundplan.pc @ONLY)
install(FILES ${CMAKE_BINARY_DIR}/groundplan.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT runtime)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME groundplan)
set(CPACK_PACKAGE_VENDOR "groundplan developers")
set(CPACK_PACKAGE_CONTACT "groundplan developers <groundplan@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Ground plans (exact union of building footprints) from 3D city models")
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)   # dependencies from the linked libraries (libgdal32, libgeos-c1v5 ...)
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS ON)   # shlibs for libgroundplan.so.0, and the ldconfig trigger
set(CPACK_DEBIAN_PACKAGE_DEPENDS "gdal-bin")
# The Python module (built for the build machine's python3) converts to Shapely and GeoPandas when asked; the CLI
# and the GDAL plugin need neither. The QGIS plugin needs QGIS.
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "python3, python3-shapely")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "python3-geopandas, qgis, openmpi-bin")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)   # Debian's; packaging/build-deb.sh also configures with it
set(CPACK_COMPONENTS_ALL runtime)
set(CPACK_DEB_COMPONENT_INSTALL OFF)
include(CPack)
