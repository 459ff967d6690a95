"""Build step of the inbetween package (the rest is in pyproject.toml): the protobuf and gRPC
stubs of inbetween/v1/inbetween.proto are generated when the package is built, into the build
tree (an editable install: into the source tree, where .gitignore keeps them out of git).

Where the proto is found, first match wins:
  1. $INBETWEEN_PROTO_ROOT (a directory holding inbetween/v1/inbetween.proto);
  2. ./proto next to this file: the copy an sdist ships (the sdist command below puts it there);
  3. ../../proto: the repository's own, for builds from a checkout (pip builds a local directory
     in place, so this relative path holds; a copy of client/python made elsewhere must keep
     proto/ two levels up or set $INBETWEEN_PROTO_ROOT).

What generates them, first found wins:
  1. protoc ($PROTOC or on PATH) with grpc_python_plugin ($GRPC_PYTHON_PLUGIN, on PATH, or
     /usr/bin): Debian's protobuf-compiler and protobuf-compiler-grpc;
  2. the grpcio-tools package (python -m grpc_tools.protoc), as pip installs it.
Neither: the build fails saying what to install. Nothing is downloaded.
"""

import importlib.util
import os
import shutil
import subprocess
import sys
from typing import List, Optional

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.command.sdist import sdist

try:
    from setuptools.errors import SetupError as _BuildError
except ImportError:  # setuptools < 59
    from distutils.errors import DistutilsSetupError as _BuildError  # type: ignore

HERE = os.path.dirname(os.path.abspath(__file__))
PROTO = os.path.join("inbetween", "v1", "inbetween.proto")


def find_proto_root() -> str:
    candidates = []
    if os.environ.get("INBETWEEN_PROTO_ROOT"):
        candidates.append(os.environ["INBETWEEN_PROTO_ROOT"])
    candidates += [os.path.join(HERE, "proto"), os.path.join(HERE, "..", "..", "proto")]
    for root in candidates:
        if os.path.isfile(os.path.join(root, PROTO)):
            return os.path.abspath(root)
    raise _BuildError(
        "inbetween: cannot find %s (looked in %s). Build from the repository's client/python, "
        "from an sdist, or set INBETWEEN_PROTO_ROOT to the directory holding it."
        % (PROTO, ", ".join(os.path.abspath(c) for c in candidates)))


def _plugin() -> Optional[str]:
    named = os.environ.get("GRPC_PYTHON_PLUGIN")
    if named:
        return named
    return shutil.which("grpc_python_plugin") or (
        "/usr/bin/grpc_python_plugin" if os.access("/usr/bin/grpc_python_plugin", os.X_OK)
        else None)


def _has_grpc_tools() -> bool:
    try:
        return importlib.util.find_spec("grpc_tools.protoc") is not None
    except ImportError:  # no grpc_tools package at all
        return False


def generate_stubs(out_dir: str) -> List[str]:
    """Writes out_dir/inbetween/v1/{__init__.py, inbetween_pb2.py, inbetween_pb2.pyi,
    inbetween_pb2_grpc.py}; returns their paths."""
    root = find_proto_root()
    target = os.path.join(out_dir, "inbetween", "v1")
    os.makedirs(target, exist_ok=True)
    outputs = ["--python_out=" + out_dir, "--pyi_out=" + out_dir, "--grpc_python_out=" + out_dir]
    protoc = os.environ.get("PROTOC") or shutil.which("protoc")
    plugin = _plugin()
    if protoc and plugin:
        command = [protoc, "-I", root, *outputs, "--plugin=protoc-gen-grpc_python=" + plugin,
                   os.path.join(root, PROTO)]
    elif _has_grpc_tools():
        command = [sys.executable, "-m", "grpc_tools.protoc", "-I", root, *outputs,
                   os.path.join(root, PROTO)]
    else:
        raise _BuildError(
            "inbetween: cannot generate the gRPC stubs: %s. Install Debian's protobuf-compiler "
            "and protobuf-compiler-grpc (or the grpcio-tools Python package), or name the tools "
            "with PROTOC and GRPC_PYTHON_PLUGIN."
            % ("protoc not found" if not protoc else "grpc_python_plugin not found"))
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            universal_newlines=True)
    if result.returncode != 0:
        raise _BuildError("inbetween: stub generation failed (%s):\n%s"
                          % (" ".join(command), result.stdout))
    init = os.path.join(target, "__init__.py")
    with open(init, "w", encoding="utf-8") as out:
        out.write('"""Generated from inbetween/v1/inbetween.proto when the package was built."""\n')
    names = ["__init__.py", "inbetween_pb2.py", "inbetween_pb2.pyi", "inbetween_pb2_grpc.py"]
    return [os.path.join(target, name) for name in names]


class BuildPyWithStubs(build_py):
    """build_py, then the stubs next to the built package."""

    def run(self) -> None:
        super().run()
        # An editable install imports the package from the source tree: the stubs go there.
        into = HERE if getattr(self, "editable_mode", False) else self.build_lib
        self._stubs = generate_stubs(into)

    def get_outputs(self, include_bytecode: bool = True) -> List[str]:  # type: ignore[override]
        return list(super().get_outputs(include_bytecode)) + list(getattr(self, "_stubs", []))


class SdistWithProto(sdist):
    """An sdist carries its own copy of the proto (./proto), so it builds anywhere."""

    def make_release_tree(self, base_dir: str, files: List[str]) -> None:
        super().make_release_tree(base_dir, files)
        target = os.path.join(base_dir, "proto", PROTO)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(os.path.join(find_proto_root(), PROTO), target)


setup(cmdclass={"build_py": BuildPyWithStubs, "sdist": SdistWithProto})
