# python/python.mk - souptet's Python module (included by the Makefile).
#
#   make                 also builds build/python/souptet (release and debug
#                        configs, when python3-dev and python3-numpy are
#                        there): PYTHONPATH=build/python python3 -c 'import souptet'
#   make install         also installs it into $(PREFIX)/lib/python3/dist-packages
#
# _core links only the C core (libsouptet); _io (wrap, .vtu) also links
# libsouptet-io (OpenVDB, VTK), and is imported only when used.

PYTHON ?= /usr/bin/python3
PY_INC := $(shell $(PYTHON) -c 'import sysconfig; print(sysconfig.get_paths()["include"])' 2>/dev/null)
PY_NUMPY_INC := $(shell $(PYTHON) -c 'import numpy; print(numpy.get_include())' 2>/dev/null)
PY_EXT := $(shell $(PYTHON) -c 'import sysconfig; print(sysconfig.get_config_var("EXT_SUFFIX"))' 2>/dev/null)
PY_SITE := $(PREFIX)/lib/python3/dist-packages

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

# Until the shared libraries exist: the static library, built with -fPIC.
$(PY_CORE): $(BUILD)/python-obj/_core.o $(LIBA)
	@mkdir -p $(dir $@)
	$(CC) -shared $(LDFLAGS_ALL) $< $(LIBA) -lxxhash $(OMPLIB) -lm -o $@
$(PY_IO): $(BUILD)/python-obj/_io.o $(LIBA)
	@mkdir -p $(dir $@)
	$(CXX) -shared $(LDFLAGS_ALL) $< $(LIBA) $(LIBS) -o $@

install-python: python
	install -d $(DESTDIR)$(PY_SITE)/souptet
	install -m 644 $(PY_PURE) $(DESTDIR)$(PY_SITE)/souptet/
	install -m 755 $(PY_CORE) $(PY_IO) $(DESTDIR)$(PY_SITE)/souptet/
install: install-python
