# blender/blender.mk - the Blender add-on's zip (included by the Makefile).
#
#   make blender-addon   $(BUILD)/souptet_cage.zip: blender/souptet_cage/ with
#                        souptet's Python module (build/python/souptet, its
#                        core extension only) and the core library
#                        libsouptet.so.0 in souptet_cage/_bundled/; Blender
#                        installs it from Edit > Preferences > Add-ons.
#
# The add-on loads _bundled/libsouptet.so.0 by path before importing the
# module, so the extension finds it whatever its RUNPATH; the library needs
# only libgomp, libxxhash, libjansson and zlib from the system. The module's VTK/OpenVDB part
# (souptet._io) stays out: the add-on writes .vtu itself. Built with the
# Python module (release and debug configs), so make check's
# tests/tools/blender.t finds it.

BL_ZIP := $(BUILD)/souptet_cage.zip
BL_STAGE := $(BUILD)/blender/souptet_cage
BL_SRC := $(sort $(wildcard blender/souptet_cage/*.py))
# The core library the extension links (absent while it links the static
# archive; then nothing to carry).
BL_LIB := $(if $(LIBSO_CORE),$(LIBSO_CORE))

.PHONY: blender-addon
ifeq ($(PY_ENABLED),yes)
all: blender-addon
blender-addon: $(BL_ZIP)
else
blender-addon:
	@echo "the Blender add-on needs souptet's Python module: python3-dev and python3-numpy (scripts/setup), config=release or debug" >&2
	@false
endif

$(BL_ZIP): $(BL_SRC) $(PY_CORE) $(PY_PURE) $(BL_LIB) blender/blender.mk
	rm -rf $(BL_STAGE) $@
	mkdir -p $(BL_STAGE)/_bundled/souptet
	cp $(BL_SRC) $(BL_STAGE)/
	cp $(PY_PURE) $(PY_CORE) $(BL_STAGE)/_bundled/souptet/
	$(if $(BL_LIB),cp -L $(BL_LIB) $(BL_STAGE)/_bundled/libsouptet.so.$(SOVERSION))
	cd $(dir $(BL_STAGE)) && $(PYTHON) -m zipfile -c $(abspath $@).tmp souptet_cage/
	mv $@.tmp $@
