# python/python.mk - souptet's Python module (included by the Makefile).
#
#   make                 also builds build/python/souptet (release and debug
#                        configs, when python3-dev and python3-numpy are
#                        there): PYTHONPATH=build/python python3 -c 'import souptet'
#   make install         also installs it where Debian's python3 finds it (PY_SITE)
#
# _core links only the C core (libsouptet); _io (wrap, .vtu) also links
# libsouptet-io (OpenVDB, VTK), and is imported only when used.

PYTHON ?= /usr/bin/python3
PY_INC := $(shell $(PYTHON) -c 'import sysconfig; print(sysconfig.get_paths()["include"])' 2>/dev/null)
PY_NUMPY_INC := $(shell $(PYTHON) -c 'import numpy; print(numpy.get_include())' 2>/dev/null)
PY_EXT := $(shell $(PYTHON) -c 'import sysconfig; print(sysconfig.get_config_var("EXT_SUFFIX"))' 2>/dev/null)
# Where Debian's python3 looks: /usr/lib/python3/dist-packages for
# PREFIX=/usr, $(PREFIX)/lib/python3.X/dist-packages otherwise (on its
# sys.path for /usr/local).
PY_VER := $(shell $(PYTHON) -c 'import sys; print("%d.%d" % sys.version_info[:2])' 2>/dev/null)
PY_SITE := $(if $(filter /usr,$(PREFIX)),/usr/lib/python3/dist-packages,$(PREFIX)/lib/python$(PY_VER)/dist-packages)

PY_OUT := $(BUILD)/python/souptet
PY_CORE := $(PY_OUT)/_core$(PY_EXT)
PY_IO := $(PY_OUT)/_io$(PY_EXT)
PY_PURE := $(PY_OUT)/__init__.py $(PY_OUT)/__init__.pyi $(PY_OUT)/py.typed
PY_CFLAGS := -std=c11 $(OPT) -Wall -Wextra -Wshadow -Wno-missing-field-initializers \
             -fPIC -fvisibility=hidden -fopenmp -Iinclude -I$(PY_INC) -I$(PY_NUMPY_INC) \
             -MMD -MP -DSOUPTET_VERSION='"$(VERSION)"' $(FP_EXACT)

# Which builds have it: not the sanitizer, fuzz or tsan builds (an ASan
# library in a plain python3 would need the runtime preloaded), and not
# where the headers are missing.
PY_ENABLED := $(if $(filter release debug,$(config)),$(if $(wildcard $(PY_INC)/Python.h),$(if $(PY_NUMPY_INC),yes)))

.PHONY: python install-python
ifeq ($(PY_ENABLED),yes)
all: python
python: $(PY_CORE) $(PY_IO) $(PY_PURE)
else
python:
	@echo "souptet's Python module needs python3-dev and python3-numpy (scripts/setup), and config=release or debug"
endif

$(BUILD)/python-obj/%.o: python/souptet/%.c python/souptet/common.h
	@mkdir -p $(dir $@)
	$(CC) $(PY_CFLAGS) -c $< -o $@

$(PY_OUT)/%: python/souptet/%
	@mkdir -p $(dir $@)
	cp $< $@

# The extensions link the shared libraries (_core libsouptet.so only, _io
# libsouptet-io.so too), found through RUNPATH: $ORIGIN/../.. in the
# build tree (build/python/souptet -> build/), $(PREFIX)/lib when
# installed (relinked into $(BUILD)/python-install).
PY_CORE_DEPS := $(LIBSO_CORE)
PY_IO_DEPS := $(LIBSO_IO) $(LIBSO_CORE)
PY_CORE_LINK = $(CC) -shared $(LDFLAGS_ALL) $< -L$(BUILD) -lsouptet -Wl,-rpath,'$(1)' -o $@
PY_IO_LINK = $(CC) -shared $(LDFLAGS_ALL) $< -L$(BUILD) -lsouptet-io -lsouptet -Wl,-rpath,'$(1)' -o $@
PY_INST := $(BUILD)/python-install
PY_INST_SO := $(PY_INST)/_core$(PY_EXT) $(PY_INST)/_io$(PY_EXT)

$(PY_CORE): $(BUILD)/python-obj/_core.o $(PY_CORE_DEPS)
	@mkdir -p $(dir $@)
	$(call PY_CORE_LINK,$$ORIGIN/../..)
$(PY_IO): $(BUILD)/python-obj/_io.o $(PY_IO_DEPS)
	@mkdir -p $(dir $@)
	$(call PY_IO_LINK,$$ORIGIN/../..)
$(PY_INST)/_core$(PY_EXT): $(BUILD)/python-obj/_core.o $(PY_CORE_DEPS)
	@mkdir -p $(dir $@)
	$(call PY_CORE_LINK,$(PREFIX)/lib)
$(PY_INST)/_io$(PY_EXT): $(BUILD)/python-obj/_io.o $(PY_IO_DEPS)
	@mkdir -p $(dir $@)
	$(call PY_IO_LINK,$(PREFIX)/lib)

ifeq ($(PY_ENABLED),yes)
install-python: python $(PY_INST_SO)
	install -d $(DESTDIR)$(PY_SITE)/souptet
	install -m 644 $(PY_PURE) $(DESTDIR)$(PY_SITE)/souptet/
	install -m 755 $(PY_INST_SO) $(DESTDIR)$(PY_SITE)/souptet/
else
install-python:
	@echo "not installing souptet's Python module (no python3-dev or python3-numpy)"
endif
install: install-python

.PHONY: uninstall-python
uninstall-python:
	rm -rf $(DESTDIR)$(PY_SITE)/souptet
uninstall: uninstall-python

# Relinked on every install (PREFIX may differ from the last one).
.PHONY: py-force
$(PY_INST_SO): py-force
