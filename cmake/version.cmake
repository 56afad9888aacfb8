# The project's version and description: the top-level CMakeLists.txt and libcf configured on its own read it.
set(CF_VERSION 0.1.0)
set(CF_DESCRIPTION "Contact-formation haptic rendering of rigid polyhedra")
