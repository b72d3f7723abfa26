# Installs the Python package; run by `cmake --install` (see CMakeLists.txt),
# so CMAKE_INSTALL_PREFIX is this install's prefix, --prefix included. Set by
# the install code before it: LPI_PYTHON (the interpreter), LPI_PYTHON_SOURCE
# (this directory), LPI_PYTHON_INSTALL_DIR (empty: ask install_dir.py),
# LPI_LIBDIR, LPI_LIBRARY_NAME (libliepoisson.so.MAJOR), LPI_PYTHON_STAGING.
#
# The package gets _install.py, naming the library installed with it: relative
# to the package (a moved or staged prefix still works) and absolute.
if(LPI_PYTHON_INSTALL_DIR)
  set(_dir "${LPI_PYTHON_INSTALL_DIR}")
  set(_how "the configured LPI_PYTHON_INSTALL_DIR")
  if(NOT IS_ABSOLUTE "${_dir}")
    set(_dir "${CMAKE_INSTALL_PREFIX}/${_dir}")
  endif()
else()
  execute_process(COMMAND "${LPI_PYTHON}" "${LPI_PYTHON_SOURCE}/install_dir.py" "${CMAKE_INSTALL_PREFIX}"
    OUTPUT_VARIABLE _out RESULT_VARIABLE _rc OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "liepoisson: ${LPI_PYTHON} could not name the Python install directory")
  endif()
  string(REPLACE "\n" ";" _out "${_out}")
  list(GET _out 0 _dir)
  list(GET _out 1 _how)
  if(_how STREQUAL "imported")
    set(_how "${LPI_PYTHON} imports it from there")
  else()
    set(_how "add ${_dir} to PYTHONPATH")
  endif()
endif()
set(_package "${_dir}/liepoisson")
set(_libdir "${LPI_LIBDIR}")
if(NOT IS_ABSOLUTE "${_libdir}")
  set(_libdir "${CMAKE_INSTALL_PREFIX}/${_libdir}")
endif()
file(RELATIVE_PATH _relative "${_package}" "${_libdir}/${LPI_LIBRARY_NAME}")
# One staging file per destination: installs to two places may run at once.
string(MD5 _key "$ENV{DESTDIR}${_package}")
set(_staged "${LPI_PYTHON_STAGING}/${_key}/_install.py")
file(WRITE "${_staged}" "\"\"\"Where this installed package finds libliepoisson (written by make install).\"\"\"
#: The library installed with this package, relative to the package's directory.
LIBRARY_RELATIVE = \"${_relative}\"
#: The same library at the path it was installed to.
LIBRARY = \"${_libdir}/${LPI_LIBRARY_NAME}\"
")
file(GLOB _sources "${LPI_PYTHON_SOURCE}/liepoisson/*.py")
file(INSTALL DESTINATION "${_package}" TYPE FILE
     FILES ${_sources} "${LPI_PYTHON_SOURCE}/liepoisson/py.typed" "${_staged}")
message(STATUS "liepoisson: Python package in ${_package} (${_how})")
