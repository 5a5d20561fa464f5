# VAHR: `make demo` runs the whole loop on this machine; `make test` runs the whole suite.
# Both do every set-up step on a fresh Debian machine and are quick when it is done.

SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
# pytest's workers. Three on two cores: much of the suite waits on brokers, stacks and
# browsers, and a third worker fills that time (with three, 1.7 of the 2 cores are busy on
# average over the suite).
WORKERS ?= 3
# Debian packages the project runs: the MQTT broker, speech (sphinxtrain's tools remake the
# hearing's acoustic adaptation), ROS 1 for the ros1 backend, chromium for the operator
# station's browser tests, and iproute2 for the ROS 2 tests' private network namespace.
DEB_PACKAGES := mosquitto espeak-ng sox chromium iproute2 ros-core python3-rospy python3-actionlib \
	python3-move-base-msgs python3-geometry-msgs python3-actionlib-msgs \
	sphinxtrain pocketsphinx sphinxbase-utils flite festival festvox-us-slt-hts
# The pure-Python ROS packages the venv sees through a .pth file (pointing the venv at all of
# Debian's dist-packages would leak its older packages, six, dateutil and a broken pynacl
# among them, into pip's view).
ROS_PYTHON_PACKAGES := actionlib actionlib_msgs catkin genmsg genpy geometry_msgs \
	move_base_msgs roscpp rosgraph rosgraph_msgs roslib rospy std_msgs
ROS_SITE := $(VENV)/ros-site
# ROS 2 (Jazzy, from PyPI) for the nav2 backend: a venv of its own, since ROS 1's and ROS 2's
# Python message packages share names. nav2_msgs has no wheel and is built into it from
# ros2/nav2_msgs (docs/robot-agent.md, "On a ROS 2 robot").
VENV_ROS2 := .venv-ros2
BIN_ROS2 := $(VENV_ROS2)/bin
# Where the tests marked ros2 are (.venv-ros2 holds the project and pytest, not every test's
# libraries, so it collects only these).
ROS2_TESTS := tests/integration/agent
# Python packages are installed by uv (pinned here, bootstrapped with pip): it resolves and
# downloads in parallel, which made a fresh set-up of both venvs about four times faster
# than pip.
UV_VERSION := 0.13.9
UV := $(BIN)/uv pip install -q
# Byte code is written and reused: the suite starts hundreds of Python processes (robots,
# stacks, browsers' servers), and each would compile the sources again without it.
unexport PYTHONDONTWRITEBYTECODE
export JSII_SILENCE_WARNING_END_OF_LIFE_NODE_VERSION := 20
export JSII_RUNTIME_PACKAGE_CACHE_ROOT := $(CURDIR)/.cache/jsii

.PHONY: hearing-adaptation sense-heard demo test test-repeat soak-test lint typecheck jstest pytest pytest-now pytest-ros2 setup system-packages bench synth deploy skill-model clean

demo: setup
	$(BIN)/vahr demo

# The suite needs only the main venv: it starts as soon as that is made, while npm's packages
# and the ROS 2 venv are made beside it (npm waits on the network; the two test files that
# use npm's tools wait for it: tests/support/node_tools.py). Then the ROS 2
# tests run beside the checks. The ROS 2 tests mostly wait (on DDS discovery, on a robot's
# goal: some 12 s of CPU in 50), and DDS discovery is slow on a busy machine, so the suite
# and the checks run at a lower priority (nice 10): the ROS 2 tests get a core when they ask
# for one, and the rest of the time goes to the suite. The last line says which parts passed.
test: system-packages
	$(MAKE) --no-print-directory -j2 $(SUITE_ENV)
	status() { case "$$1" in 0) echo passed;; -) echo "not run";; *) echo "FAILED (exit $$1)";; esac; }; \
	VAHR_AWAIT_NODE_MODULES=1 nice -n 10 $(MAKE) --no-print-directory pytest-now & suite=$$!; \
	$(MAKE) --no-print-directory -j2 node_modules/.installed $(VENV_ROS2)/.installed; setup=$$?; \
	checks=-; ros2=-; \
	if [ $$setup = 0 ]; then \
		nice -n 10 $(MAKE) --no-print-directory -j3 --output-sync=target lint typecheck jstest & checks=$$!; \
		$(MAKE) --no-print-directory pytest-ros2; ros2=$$?; \
		wait $$checks; checks=$$?; \
	fi; \
	wait $$suite; suite=$$?; \
	echo "make test: set-up $$(status $$setup), suite $$(status $$suite), checks $$(status $$checks), ROS 2 tests $$(status $$ros2)"; \
	[ $$setup = 0 ] && [ $$suite = 0 ] && [ $$checks = 0 ] && [ $$ros2 = 0 ]

# What the suite needs: the main venv and ROS 1's Python packages in it. The checks (lint,
# types, the page's JS) need npm's packages too, not the ROS 2 venv.
SUITE_ENV := $(VENV)/.installed $(ROS_SITE)/.linked
CHECK_ENV := $(SUITE_ENV) node_modules/.installed

# The environments are made side by side: npm and uv wait on the network while the ROS 2
# messages compile. The ASK CLI is for deploying only (docs/deploy.md): set-up adds it after
# the tools the tests use; `make test` leaves it out (no test runs it).
setup: system-packages
	$(MAKE) --no-print-directory -j3 $(CHECK_ENV) $(VENV_ROS2)/.installed $(ASK_CLI)

system-packages:
	@missing=$$(for p in $(DEB_PACKAGES); do dpkg-query -W -f='$${Status}' $$p 2>/dev/null \
		| grep -q 'ok installed' || echo $$p; done); \
	if [ -n "$$missing" ]; then \
		if [ "$$(id -u)" = 0 ]; then \
			echo "Installing Debian packages: $$missing"; \
			apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null; \
		else \
			echo "Missing Debian packages. Run: sudo apt-get update && sudo apt-get install -y $$missing"; \
			exit 1; \
		fi; \
	fi

# The venv is made without pip and uv is put into it by the system's pip when there is one:
# venv's own pip install (ensurepip) took 9 s of a fresh set-up's first 30, with nothing else
# able to start. The venv's pip (the Lambda bundle is built with it) then comes, pinned, from
# requirements-dev.txt.
$(VENV)/.installed: requirements.txt requirements-dev.txt pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv --without-pip $(VENV)
	$(BIN)/uv --version 2>/dev/null | grep -q "^uv $(UV_VERSION) " || \
	if $(PYTHON) -m pip --version >/dev/null 2>&1; then \
		$(PYTHON) -m pip --python $(BIN)/python install -q uv==$(UV_VERSION); \
	else \
		$(BIN)/python -m ensurepip >/dev/null && $(BIN)/python -m pip install -q uv==$(UV_VERSION); \
	fi
	$(UV) --python $(BIN)/python -r requirements-dev.txt
	$(UV) --python $(BIN)/python --no-deps --no-build-isolation -e .
	touch $@

$(ROS_SITE)/.linked: $(VENV)/.installed
	mkdir -p $(ROS_SITE)
	for p in $(ROS_PYTHON_PACKAGES); do ln -sfn /usr/lib/python3/dist-packages/$$p $(ROS_SITE)/$$p; done
	echo "$(CURDIR)/$(ROS_SITE)" > $$($(BIN)/python -c 'import sysconfig; print(sysconfig.get_path("purelib"))')/vahr-ros.pth
	touch $@

# ROS 2 Jazzy's wheels (pinned) and nav2_msgs built into the venv; then the project itself at
# the main venv's versions of its dependencies (a change there does not rebuild nav2_msgs).
# uv makes the venv in a second (venv's own module took 13 s installing a pip nothing uses).
$(VENV_ROS2)/.ros2: $(VENV)/.installed requirements-ros2.txt ros2/build-nav2-msgs.sh ros2/nav2_msgs/package.xml \
		ros2/nav2_msgs/CMakeLists.txt ros2/nav2_msgs/action/NavigateToPose.action
	test -x $(BIN_ROS2)/python || $(BIN)/uv venv -q --python-preference only-system --python $(PYTHON) $(VENV_ROS2)
	$(UV) --python $(BIN_ROS2)/python -r requirements-ros2.txt
	ros2/build-nav2-msgs.sh $(VENV_ROS2) .build/ros2-nav2-msgs
	touch $@

$(VENV_ROS2)/.installed: $(VENV_ROS2)/.ros2 requirements.txt pyproject.toml
	$(UV) --python $(BIN_ROS2)/python -c requirements.txt --no-build-isolation -e .
	touch $@

# npm's packages for the checks and the tests: the CDK CLI and TypeScript, not the
# workspaces (the ASK CLI's 500 packages, 30-40 s to install, are used only to deploy: the
# tests that use npm's tools wait for this marker, not for them).
node_modules/.installed: package.json package-lock.json tools/ask-cli/package.json
	npm ci --workspaces=false --no-audit --no-fund --loglevel=error
	touch $@

# The pinned ASK CLI (the workspace tools/ask-cli), added at the lock's versions: `npx ask`.
ASK_CLI := node_modules/.ask-cli
$(ASK_CLI): node_modules/.installed
	npm install --workspace=tools/ask-cli --no-save --no-audit --no-fund --loglevel=error
	touch $@

lint: system-packages $(CHECK_ENV)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check --quiet .
	$(BIN)/python -m vahr.skill_model --check
	$(BIN)/lint-imports --no-cache
	$(BIN)/python -m vahr.station.contract --check
	npx tsc -p vahr/station

# The station page's own logic in Node's test runner (tests/js/*.test.mjs): the map's motion
# and the participant's interaction time. A failing test exits non-zero, and so does make.
jstest: system-packages $(CHECK_ENV)
	node --test tests/js/

typecheck: system-packages $(CHECK_ENV)
	$(BIN)/mypy

# Each test file runs whole on one of $(WORKERS) workers, the longest files first
# (tests/support/scheduling.py). The 90 s soak is not among them: `make soak-test`.
SUITE_TESTS := -m "not soak and not ros2"
SUITE = $(BIN)/pytest -q -n $(WORKERS) --dist loadgroup $(SUITE_TESTS)
pytest: setup
	$(SUITE)

# The suite without making anything first: `make test` has made what it needs. One process
# collects it first: in a fresh clone no byte code is written yet, and each of the workers
# would compile the suite's modules and their libraries at the same time (three cold
# collections took 103 s of CPU here; one, then three warm ones, 90 s, and the machine's
# other core was making the ROS 2 venv meanwhile). A collection error is the suite's to
# report, at once after.
pytest-now:
	$(BIN)/pytest -q --collect-only -p no:xdist $(SUITE_TESTS) >/dev/null 2>&1 || true
	$(SUITE)

# The tests marked ros2 (the nav2 backend against real rclpy and Fast DDS) in .venv-ros2, in a
# private network namespace where one can be made (root, as CI is): no DDS packet leaves it
# and no other process's DDS meets these. Inside, each test's ROS graph has a domain of its
# own and discovery stays on localhost (tests/support/nav2.py). One file at a time: under
# `make test` they already run beside the suite and the checks.
ROS2_PYTEST := $(BIN_ROS2)/pytest -q -m ros2 $(ROS2_TESTS)
pytest-ros2: system-packages $(VENV_ROS2)/.installed
	if [ "$$(id -u)" = 0 ] && unshare -n true 2>/dev/null; then \
		unshare -n sh -c 'ip link set lo up && exec $(ROS2_PYTEST)'; \
	else \
		$(ROS2_PYTEST); \
	fi

# The 90 s soak (docs/reliability.md): every fault under load. Not part of `make test`.
soak-test: setup
	$(BIN)/pytest -q -m soak tests/integration/soak

# The integration tests (processes, brokers, timing) five times in a row: a test that
# passes only most of the time fails here (see docs/reliability.md).
test-repeat: setup
	for run in 1 2 3 4 5; do echo "integration run $$run of 5"; \
		$(SUITE) tests/integration || exit 1; done

bench: setup
	for script in bench/*.py; do case $$script in */_*) continue;; esac; $(BIN)/python $$script || exit 1; done

synth: setup
	npx cdk synth --quiet

# Deploy to the AWS account of the current credentials; CDK_ARGS takes context flags such as
# `-c lex=true -c skill=true` (see docs/deploy.md), then point skill.json at the function.
deploy: setup
	npx cdk deploy --outputs-file cdk-outputs.json $(CDK_ARGS)
	$(BIN)/python -m infra.skill_endpoint --outputs cdk-outputs.json

skill-model: setup
	$(BIN)/python -m vahr.skill_model

clean:
	rm -rf $(VENV) $(VENV_ROS2) node_modules cdk.out .build .cache .state

# Remake robot_agent/voice/data/espeak-ng/, the hearing's adaptation to espeak-ng (docs/voice.md;
# about 17 minutes on 2 cores, and some 2.5 GB of temporary disk for the clips).
hearing-adaptation: setup
	$(BIN)/python -m robot_agent.voice.adaptation

# Remake robot_agent/voice/data/answer-sense-heard.yaml, the sense check's training sentences as
# the robot hears them (docs/history/voice-tuning.md, "The ninth round"; about ten minutes on 2 cores).
sense-heard: setup
	$(BIN)/python -m robot_agent.voice.sense_heard
