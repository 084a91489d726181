# Two commands do all the set-up on a fresh machine: `make demo` and `make test`.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
export MPLBACKEND := Agg

.PHONY: demo test test-slow bench docs sysdeps clean

# openseespy needs the Debian packages libblas3 and liblapack3; the FMU
# export compiles its binary with gcc and cmake; the report's test renders
# the page in Chromium.
sysdeps:
	@libs="$$( (ldconfig -p || /sbin/ldconfig -p) 2>/dev/null)"; missing=""; \
	echo "$$libs" | grep -q 'libblas.so.3' || missing="$$missing libblas3"; \
	echo "$$libs" | grep -q 'liblapack.so.3' || missing="$$missing liblapack3"; \
	command -v gcc >/dev/null || missing="$$missing gcc libc6-dev"; \
	command -v cmake >/dev/null || missing="$$missing cmake"; \
	command -v make >/dev/null || missing="$$missing make"; \
	command -v chromium >/dev/null || missing="$$missing chromium"; \
	if [ -z "$$missing" ]; then :; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	  echo "installing$$missing"; \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null; \
	elif command -v sudo >/dev/null && sudo -n true 2>/dev/null && command -v apt-get >/dev/null; then \
	  echo "installing$$missing with sudo"; \
	  sudo -n apt-get update -qq && sudo -n env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null; \
	else echo "fvd_bridge: needs the Debian packages$$missing; run: sudo apt-get install -y$$missing" >&2; exit 2; fi

$(STAMP): pyproject.toml
	@$(MAKE) --no-print-directory sysdeps
	test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e '.[test]'
	touch $(STAMP)

# the paper's procedure at full settings: about 2 minutes on 2 cores
demo: $(STAMP)
	$(BIN)/fvd-bridge demo --out demo_out

test: $(STAMP)
	$(BIN)/python -m pytest -q -n 2 --dist loadfile -m "not slow"

# the documentation site (MkDocs, warnings are errors) into site/
docs: $(STAMP)
	$(BIN)/python -m mkdocs build --strict --site-dir site

# the long end-to-end checks (.ci/run runs them after make test)
test-slow: $(STAMP)
	$(BIN)/python -m pytest -q -n 2 --dist loadfile -m slow

bench: $(STAMP)
	$(BIN)/python -m pip install -q -e '.[bench]'
	for b in benchmarks/bench_*.py; do $(BIN)/python $$b || exit 1; done

clean:
	rm -rf $(VENV) demo_out *.egg-info
