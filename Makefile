# souptet - one non-recursive GNU Makefile.
#
#   make                  library, tools, tests, Python module, Blender add-on into build/
#   make tools            the tools alone (build/bin/<tool>)
#   make check            install missing Debian packages, build, run all tests
#   make demo             the main job on the bundled model
#   make demo-sim         the bundled model's cage in a FEM solve (SfePy)
#   make demo-sim-parts   two materials from soupmesh --parts in a FEM solve (SfePy)
#   make bench            measurements against peers (bench/results/)
#   make install PREFIX=/usr/local DESTDIR=
#   make fuzz [FUZZ_SECONDS=60] [FUZZ_RUNS=N]  libFuzzer on every reader (build-fuzz/)
#   make config=debug|sanitize ...   (objects go to build/ or build-<config>/)
#   make config=tsan check   the threaded tests under ThreadSanitizer (clang)

config ?= release
PREFIX ?= /usr/local
DESTDIR ?=
VERSION := 0.1.0

ifeq ($(config),release)
  BUILD := build
  OPT := -O2 -g
else ifeq ($(config),debug)
  BUILD := build-debug
  OPT := -O0 -g3
else ifeq ($(config),sanitize)
  BUILD := build-sanitize
  OPT := -O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
else ifeq ($(config),fuzz)
  # libFuzzer harnesses (make fuzz): clang, the library instrumented for
  # coverage, ASan and UBSan.
  BUILD := build-fuzz
  CC := clang
  CXX := clang++
  OMPLIB := -lomp
  OPT := -O1 -g -fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer \
         -fno-sanitize-recover=undefined
else ifeq ($(config),tsan)
  # ThreadSanitizer over the threaded code (make config=tsan check): clang
  # and LLVM's OpenMP runtime, whose Archer tool tells TSan about OpenMP's
  # barriers and reductions (GCC's libgomp would give false reports).
  BUILD := build-tsan
  CC := clang
  CXX := clang++
  OMPLIB := -lomp
  OPT := -O1 -g -fsanitize=thread -fno-omit-frame-pointer
else
  $(error config must be release, debug, sanitize, fuzz or tsan)
endif

CC ?= cc
CXX ?= c++
OMPLIB ?= -lgomp
# IEEE double as the predicates' error bounds assume, whatever the user's
# CFLAGS say (so these come after them: the last flag wins). -ffp-contract=off:
# fused multiply-adds would change rounding behind the back of the error
# bounds in the predicates and the exact distances; the rest undo
# -ffast-math, -Ofast and their parts (src/base/fpenv.h refuses to compile under
# the ones a macro shows, for builds that do not go through this file).
FP_EXACT := -fno-fast-math -fno-unsafe-math-optimizations -fno-associative-math \
            -fno-reciprocal-math -fno-finite-math-only -fsigned-zeros -ffp-contract=off
WARN := -Wall -Wextra -Wshadow -Wpointer-arith -Wformat=2 -Wundef
CFLAGS_ALL := -std=c11 -D_POSIX_C_SOURCE=200809L $(OPT) $(WARN) -Wstrict-prototypes \
              -fopenmp -Iinclude -MMD -MP \
              -DSOUPTET_VERSION='"$(VERSION)"' $(CFLAGS) $(FP_EXACT)
CXXFLAGS_ALL := -std=c++17 $(OPT) -Wall -Wextra -fopenmp -Iinclude \
                -I/usr/include/vtk-9.1 -MMD -MP -DSOUPTET_VERSION='"$(VERSION)"' $(CXXFLAGS) \
                $(FP_EXACT)
LIBS = $(IO_LIBS) $(CORE_LIBS) -lpthread
LDFLAGS_ALL := $(OPT) -fopenmp $(LDFLAGS)

# Two libraries. libsouptet: the C core (soups, fields, signs, lattices,
# fit, embedding, the .msh/.node/.ele/.mesh formats), needing libgomp,
# libxxhash, libjansson (glTF's JSON), zlib and libm alone: what the
# Python module and the Blender add-on link. libsouptet-io: what needs OpenVDB or VTK (.vdb/.vti fields, the
# .vtu front door, the wrap's volumeToMesh), on top of the core: what the
# tools link too. Each as a static archive (the tools and tests) and a
# shared library with a soname, exporting only the names its public
# headers declare (scripts/exports writes the version scripts).
# The library's C files are in the folders of its layers, src/LAYER/
# (src/MODULES; scripts/layout puts them there): libsouptet-io's are the
# layer io's, src/io/.
LIB_C    := $(filter-out src/adapters/% src/cli/% src/tools/%,$(sort $(wildcard src/*.c src/*/*.c)))
IO_C     := $(filter src/io/%,$(LIB_C))
ifeq ($(IO_C),)
  # A flat src/ that scripts/layout has not laid out yet: by name.
  IO_C := $(filter $(addprefix src/,gridio.c gridio_path.c tetio.c tetio_write.c vtkxml.c wrap.c),$(LIB_C))
endif
CORE_C   := $(filter-out $(IO_C),$(LIB_C))
LIB_CXX  := $(sort $(wildcard src/adapters/*.cpp))
# The VTK adapters are a library of their own, libsouptet-vtk.so.0, that
# libsouptet-io opens on first use (src/adapters/gridio_internal.h): with
# vtkxml.c's checks (also in libsouptet-io.a, for the tests that call them).
VTK_CXX  := $(addprefix src/adapters/,gridio_vti.cpp tetio_vtu.cpp vtk_capture.cpp tetio_plugin.cpp)
TOOLS   := $(basename $(notdir $(sort $(wildcard src/tools/*.c))))
TESTS_C := $(basename $(notdir $(sort $(wildcard tests/test_*.c))))

CORE_OBJ := $(CORE_C:src/%.c=$(BUILD)/obj/%.o)
IO_OBJ   := $(IO_C:src/%.c=$(BUILD)/obj/%.o) $(patsubst src/%.cpp,$(BUILD)/obj/%.o,$(filter-out $(VTK_CXX),$(LIB_CXX)))
VTK_OBJ  := $(VTK_CXX:src/%.cpp=$(BUILD)/obj/%.o) $(filter %/vtkxml.o,$(IO_OBJ))
LIB_OBJ  := $(CORE_OBJ) $(IO_OBJ) $(filter-out $(IO_OBJ),$(VTK_OBJ))
CLI_OBJ := $(patsubst src/%.c,$(BUILD)/obj/%.o,$(sort $(wildcard src/cli/*.c)))
LIBA_CORE := $(BUILD)/libsouptet.a
LIBA_IO   := $(BUILD)/libsouptet-io.a
LIBA      := $(LIBA_IO) $(LIBA_CORE)
SOVERSION := 0
LIBSO_CORE := $(BUILD)/libsouptet.so.$(VERSION)
LIBSO_IO   := $(BUILD)/libsouptet-io.so.$(VERSION)
LIBSO_VTK  := $(BUILD)/libsouptet-vtk.so.$(VERSION)
CORE_LIBS := -lxxhash -ljansson -lz $(OMPLIB) -lm
IO_LIBS   := -lopenvdb -ltbb -lImath-3_1
VTK_LIBS  := -lvtkIOXML-9.1 -lvtkIOXMLParser-9.1 -lvtkIOCore-9.1 -lvtkCommonExecutionModel-9.1 \
        -lvtkCommonDataModel-9.1 -lvtkCommonMath-9.1 -lvtkCommonCore-9.1 -lvtksys-9.1
TOOL_BIN := $(TOOLS:%=$(BUILD)/bin/%)
TEST_BIN := $(TESTS_C:%=$(BUILD)/tests/%)

.PHONY: all tools check test demo demo-sim demo-sim-parts bench setup install uninstall clean fuzz
all: $(LIBA) $(LIBSO_CORE) $(LIBSO_IO) $(LIBSO_VTK) $(TOOL_BIN) $(TEST_BIN)
# Objects stay after a build: make would delete the tools' and tests'
# objects as intermediates, and the next target would compile them again.
.SECONDARY:
# The tools alone (what the demos run): no unit tests, Python or Blender.
tools: $(TOOL_BIN) $(LIBSO_VTK)

# The library's objects are position-independent (they go into the shared
# libraries too); the tools' and tests' are not.
$(LIB_OBJ): CFLAGS_ALL += -fPIC
$(LIB_OBJ): CXXFLAGS_ALL += -fPIC

# The flags a build was made with, in $(BUILD)/flags: rewritten when they
# change (other CFLAGS, a new compiler), and every object depends on it,
# so a changed flag rebuilds what it touches instead of being silently
# ignored on a built tree.
FLAGS_NOW := $(CC) $(CXX) | $(CFLAGS_ALL) | $(CXXFLAGS_ALL) | $(LDFLAGS_ALL) | library -fPIC
ifneq ($(FLAGS_NOW),$(file < $(BUILD)/flags))
  $(shell mkdir -p $(BUILD))
  $(file > $(BUILD)/flags,$(FLAGS_NOW))
endif
$(LIB_OBJ) $(CLI_OBJ): $(BUILD)/flags

# What --version prints: VERSION and the commit, from git describe in a
# clone, else from the file COMMIT (git archive writes the commit into it:
# .gitattributes export-subst), else "unknown". Rewritten only when it
# changes, so only the CLI's objects rebuild.
COMMIT := $(strip $(if $(wildcard .git),$(shell git describe --always --dirty --abbrev=12 2>/dev/null)))
ifeq ($(COMMIT),)
  COMMIT := $(strip $(shell sed -n '/^[0-9a-f]\{7,\}/p' COMMIT 2>/dev/null | head -1))
endif
COMMIT := $(if $(COMMIT),$(COMMIT),unknown)
BUILD_H_NOW := \#define SOUPTET_COMMIT "$(COMMIT)"
ifneq ($(BUILD_H_NOW),$(file < $(BUILD)/gen/souptet_build.h))
  $(shell mkdir -p $(BUILD)/gen)
  $(file > $(BUILD)/gen/souptet_build.h,$(BUILD_H_NOW))
endif
$(CLI_OBJ): $(BUILD)/gen/souptet_build.h
$(CLI_OBJ): CFLAGS_ALL += -I$(BUILD)/gen

$(BUILD)/obj/%.o: src/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) -c $< -o $@
$(BUILD)/obj/%.o: src/%.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS_ALL) -c $< -o $@
$(BUILD)/obj/cli/%.o: src/cli/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) -c $< -o $@
$(BUILD)/obj/tools/%.o: src/tools/%.c $(BUILD)/flags
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) -c $< -o $@
$(BUILD)/obj/tests/%.o: tests/%.c $(BUILD)/flags
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) -Itests -c $< -o $@

$(LIBA_CORE): $(CORE_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@
	ar rcs $@ $^
$(LIBA_IO): $(IO_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@
	ar rcs $@ $^

# Shared libraries: libNAME.so.VERSION, its soname libNAME.so.0 and the
# development link libNAME.so beside it. Undefined symbols are an error,
# except under the sanitizers (whose runtime the executable brings).
ifneq ($(filter release debug,$(config)),)
  SO_LDFLAGS := -Wl,--no-undefined
endif
# The same for what the links are made with ($(BUILD)/linkflags): a new
# library or link option relinks the libraries, tools and tests of a built
# tree, which their objects alone would not.
TOOL_LINK := -Wl,--as-needed
# The programs export the core's names (st_*) for the VTK plugin to bind
# to, and find it beside their folder: $(BUILD)/bin -> $(BUILD), or
# PREFIX/bin -> PREFIX/lib.
EXE_LINK := -Wl,--dynamic-list=$(BUILD)/exe.dynlist -Wl,-rpath,'$$ORIGIN/..:$$ORIGIN/../lib'
# Written here as the flags are (a file make cannot forget to make).
EXE_DYNLIST := { st_*; };
VTK_MAP := SOUPTET_VTK_0 { global: st_vtk_plugin_entry; local: *; };
ifneq ($(EXE_DYNLIST),$(file < $(BUILD)/exe.dynlist))
  $(shell mkdir -p $(BUILD))
  $(file > $(BUILD)/exe.dynlist,$(EXE_DYNLIST))
endif
ifneq ($(VTK_MAP),$(file < $(BUILD)/libsouptet-vtk.map))
  $(shell mkdir -p $(BUILD))
  $(file > $(BUILD)/libsouptet-vtk.map,$(VTK_MAP))
endif
LINK_NOW := $(LDFLAGS_ALL) | $(SO_LDFLAGS) | $(CORE_LIBS) | $(IO_LIBS) | $(VTK_LIBS) | $(LIBS) | $(TOOL_LINK) | $(EXE_LINK)
ifneq ($(LINK_NOW),$(file < $(BUILD)/linkflags))
  $(shell mkdir -p $(BUILD))
  $(file > $(BUILD)/linkflags,$(LINK_NOW))
endif
$(BUILD)/libsouptet.map: $(CORE_OBJ) $(IO_OBJ) scripts/exports $(wildcard include/souptet/*.h)
	scripts/exports SOUPTET_0 $(CORE_OBJ) -- $(IO_OBJ) > $@.tmp && mv $@.tmp $@
$(BUILD)/libsouptet-io.map: $(IO_OBJ) scripts/exports $(wildcard include/souptet/*.h)
	scripts/exports SOUPTET_IO_0 $(IO_OBJ) -- > $@.tmp && mv $@.tmp $@
$(LIBSO_CORE): $(CORE_OBJ) $(BUILD)/libsouptet.map $(BUILD)/linkflags
	$(CC) -shared $(LDFLAGS_ALL) $(SO_LDFLAGS) -Wl,-soname,libsouptet.so.$(SOVERSION) \
	  -Wl,--version-script=$(BUILD)/libsouptet.map $(CORE_OBJ) $(CORE_LIBS) -o $@
	ln -sf $(notdir $@) $(BUILD)/libsouptet.so.$(SOVERSION)
	ln -sf libsouptet.so.$(SOVERSION) $(BUILD)/libsouptet.so
$(LIBSO_IO): $(IO_OBJ) $(LIBSO_CORE) $(BUILD)/libsouptet-io.map $(BUILD)/linkflags
	$(CXX) -shared $(LDFLAGS_ALL) $(SO_LDFLAGS) -Wl,-soname,libsouptet-io.so.$(SOVERSION) \
	  -Wl,--version-script=$(BUILD)/libsouptet-io.map $(IO_OBJ) -L$(BUILD) -lsouptet \
	  -Wl,-rpath,'$$ORIGIN' -Wl,--as-needed $(IO_LIBS) $(CORE_LIBS) -o $@
	ln -sf $(notdir $@) $(BUILD)/libsouptet-io.so.$(SOVERSION)
	ln -sf libsouptet-io.so.$(SOVERSION) $(BUILD)/libsouptet-io.so
# The plugin exports its table alone; the core's names it leaves to the
# program, or to libsouptet.so.0 (NEEDED, found beside it).
$(LIBSO_VTK): $(VTK_OBJ) $(LIBSO_CORE) $(BUILD)/libsouptet-vtk.map $(BUILD)/linkflags
	$(CXX) -shared $(LDFLAGS_ALL) $(SO_LDFLAGS) -Wl,-soname,libsouptet-vtk.so.$(SOVERSION) \
	  -Wl,--version-script=$(BUILD)/libsouptet-vtk.map $(VTK_OBJ) -L$(BUILD) -lsouptet \
	  -Wl,-rpath,'$$ORIGIN' -Wl,--as-needed $(VTK_LIBS) $(CORE_LIBS) -o $@
	ln -sf $(notdir $@) $(BUILD)/libsouptet-vtk.so.$(SOVERSION)

# Tools and tests link with the C++ driver: the adapters need libstdc++.
# A tool keeps only the libraries it calls (--as-needed): one that reads
# and writes no field or .vtu input (soupmesh) then loads neither OpenVDB
# nor VTK, whose relocations cost a process about 60 ms (issue 41).
$(BUILD)/bin/%: $(BUILD)/obj/tools/%.o $(CLI_OBJ) $(LIBA) $(BUILD)/linkflags
	@mkdir -p $(dir $@)
	$(CXX) $(LDFLAGS_ALL) $(EXE_LINK) $< $(CLI_OBJ) $(LIBA) $(TOOL_LINK) $(LIBS) -o $@
$(BUILD)/tests/%: $(BUILD)/obj/tests/%.o $(LIBA) $(BUILD)/linkflags
	@mkdir -p $(dir $@)
	$(CXX) $(LDFLAGS_ALL) $(EXE_LINK) $< $(LIBA) $(LIBS) -o $@

# Peers for make bench (not installed).
BENCH_BIN := $(BUILD)/bench/vdb_udf $(BUILD)/bench/vdb_dist $(BUILD)/bench/stream26 $(BUILD)/bench/iou \
             $(BUILD)/bench/alpha_wrap $(BUILD)/bench/cgal_mesh3 $(BUILD)/bench/gwn
# CGAL's exact kernels need GMP and MPFR; its headers want -frounding-math.
$(BUILD)/bench/alpha_wrap $(BUILD)/bench/cgal_mesh3: LIBS += -lgmp -lmpfr
$(BUILD)/bench/alpha_wrap $(BUILD)/bench/cgal_mesh3: CXXFLAGS_ALL += -frounding-math -DNDEBUG
# vtkxml.c's own XML lexer against expat (the measurement of issue 39; not
# in make bench, needs libexpat1-dev): make build/bench/vtkxml_expat
$(BUILD)/bench/vtkxml_expat: LIBS += -lexpat
$(BUILD)/bench/vtkxml_expat: CFLAGS_ALL += -Isrc
# soupdist's job through OpenVDB as a whole process: its start links what it
# uses (--as-needed, as the tools), no VTK.
$(BUILD)/bench/vdb_dist: bench/vdb_dist.cpp $(LIBA)
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS_ALL) $< $(LIBA) -Wl,--as-needed $(LIBS) -o $@
$(BUILD)/bench/%: bench/%.cpp $(LIBA)
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS_ALL) $(EXE_LINK) $< $(LIBA) $(LIBS) -o $@
$(BUILD)/bench/%: bench/%.c $(LIBA)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) -c $< -o $@.o
	$(CXX) $(LDFLAGS_ALL) $(EXE_LINK) $@.o $(LIBA) $(LIBS) -o $@

# libFuzzer harnesses, one per reader (fuzz/fuzz_*.c), built with clang in
# build-fuzz/ and run by scripts/fuzz for FUZZ_SECONDS each (FUZZ_RUNS=N:
# N executions each instead, FUZZ_SECONDS still caps the time).
FUZZ_SECONDS ?= 60
FUZZ_BIN := $(patsubst fuzz/%.c,$(BUILD)/fuzz/%,$(sort $(wildcard fuzz/fuzz_*.c)))
$(BUILD)/fuzz/%: fuzz/%.c $(LIBA)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) -fsanitize=fuzzer -c $< -o $@.o
	$(CXX) $(LDFLAGS_ALL) $(EXE_LINK) -fsanitize=fuzzer $@.o $(LIBA) $(LIBS) -o $@

ifeq ($(config),fuzz)
fuzz: $(FUZZ_BIN)
	scripts/fuzz $(BUILD)/fuzz $(FUZZ_SECONDS)
else
fuzz:
	@scripts/setup --fuzz
	$(MAKE) --no-print-directory config=fuzz fuzz
endif

# scripts/setup installs what is missing and returns in a second otherwise.
setup:
	@scripts/setup

# The README's test command. Unit tests are TAP programs; tool tests are
# TAP shell scripts; prove runs them all and prints the count.
# The unit tests of the modules with OpenMP loops, run under TSan with 3
# threads (more than the 2 cores, so threads interleave), Archer loaded.
TSAN_TESTS := test_cancel test_dist test_sign test_holes test_shells test_mincut test_lattice \
              test_sculpt test_fair test_fit test_enclose test_embed test_tetstat \
              test_tetmesh test_solid test_soupinfo test_wrap
ifeq ($(config),tsan)
check:
	@scripts/setup --fuzz
	$(MAKE) --no-print-directory $(TSAN_TESTS:%=$(BUILD)/tests/%)
	OMP_NUM_THREADS=3 OMP_TOOL_LIBRARIES=$$(clang -print-resource-dir)/../../libarcher.so \
	  TSAN_OPTIONS="halt_on_error=1 ignore_noninstrumented_modules=1 suppressions=$(CURDIR)/tests/tsan.supp" \
	  prove --exec '' --timer $(TSAN_TESTS:%=$(BUILD)/tests/%)
else
# ASAN_OPTIONS: LeakSanitizer's tracking of dynamic TLS (__tls_get_addr)
# can misread glibc's DTV at exit and crash the leak check ("Tracer caught
# signal 11", google/sanitizers#1322): a tool that ran and wrote its file
# then exits 1. Seen on soupsign -o .vti, depending on memory layout alone.
# Off, only dynamic TLS goes unscanned, which can add a false leak report,
# never hide one (our TLS is static).
check: setup
	$(MAKE) --no-print-directory all
	SOUPTET_BIN=$(CURDIR)/$(BUILD)/bin SOUPTET_TESTBIN=$(CURDIR)/$(BUILD)/tests \
	  ASAN_OPTIONS=intercept_tls_get_addr=0 \
	  LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp:print_suppressions=0 \
	  prove --exec '' --timer $(TEST_BIN) $(sort $(wildcard tests/tools/*.t))
endif

test: check

demo: setup
	$(MAKE) --no-print-directory tools
	scripts/demo $(BUILD)/bin

demo-sim: setup
	$(MAKE) --no-print-directory tools
	scripts/simulate $(BUILD)/bin demo

demo-sim-parts: setup
	$(MAKE) --no-print-directory tools
	scripts/simulate-parts $(BUILD)/bin demo

bench: setup
	@scripts/setup --bench
	$(MAKE) --no-print-directory all $(BENCH_BIN)
	scripts/bench $(BUILD) $(STAGE)

install: all
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/lib/pkgconfig \
	  $(DESTDIR)$(PREFIX)/include/souptet $(DESTDIR)$(PREFIX)/share/man/man1 \
	  $(DESTDIR)$(PREFIX)/share/man/man7
	install -m 755 $(TOOL_BIN) $(DESTDIR)$(PREFIX)/bin/
	install -m 644 $(LIBA) $(DESTDIR)$(PREFIX)/lib/
	install -m 755 $(LIBSO_CORE) $(LIBSO_IO) $(LIBSO_VTK) $(DESTDIR)$(PREFIX)/lib/
	ln -sf libsouptet-vtk.so.$(VERSION) $(DESTDIR)$(PREFIX)/lib/libsouptet-vtk.so.$(SOVERSION)
	for l in libsouptet libsouptet-io; do \
	  ln -sf $$l.so.$(VERSION) $(DESTDIR)$(PREFIX)/lib/$$l.so.$(SOVERSION) && \
	  ln -sf $$l.so.$(SOVERSION) $(DESTDIR)$(PREFIX)/lib/$$l.so || exit 1; done
	install -m 644 include/souptet/*.h $(DESTDIR)$(PREFIX)/include/souptet/
	install -m 644 man/man1/*.1 $(DESTDIR)$(PREFIX)/share/man/man1/
	install -m 644 man/man7/*.7 $(DESTDIR)$(PREFIX)/share/man/man7/
	sed -e 's|@PREFIX@|$(PREFIX)|g' -e 's|@VERSION@|$(VERSION)|g' \
	    -e 's|@LIBS@|$(CORE_LIBS)|g' souptet.pc.in > $(DESTDIR)$(PREFIX)/lib/pkgconfig/souptet.pc
	sed -e 's|@PREFIX@|$(PREFIX)|g' -e 's|@VERSION@|$(VERSION)|g' \
	    -e 's|@LIBS@|$(IO_LIBS) -lstdc++|g' souptet-io.pc.in > $(DESTDIR)$(PREFIX)/lib/pkgconfig/souptet-io.pc
	-[ -z "$(DESTDIR)" ] && command -v ldconfig >/dev/null && ldconfig

uninstall:
	rm -f $(TOOLS:%=$(DESTDIR)$(PREFIX)/bin/%) $(DESTDIR)$(PREFIX)/lib/libsouptet.a \
	  $(DESTDIR)$(PREFIX)/lib/libsouptet-io.a $(DESTDIR)$(PREFIX)/lib/libsouptet.so* \
	  $(DESTDIR)$(PREFIX)/lib/libsouptet-io.so* $(DESTDIR)$(PREFIX)/lib/libsouptet-vtk.so* \
	  $(DESTDIR)$(PREFIX)/lib/pkgconfig/souptet.pc $(DESTDIR)$(PREFIX)/lib/pkgconfig/souptet-io.pc
	rm -rf $(DESTDIR)$(PREFIX)/include/souptet
	rm -f $(TOOLS:%=$(DESTDIR)$(PREFIX)/share/man/man1/%.1) $(DESTDIR)$(PREFIX)/share/man/man7/souptet.7

clean:
	rm -rf build build-debug build-sanitize build-fuzz build-tsan

include python/python.mk

-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)
include blender/blender.mk
