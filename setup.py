"""`pip install .`: builds the strahl Python module with the project's CMake
(python/CMakeLists.txt) and installs it with libstrahl, the plugins and the
shaders beside it (site-packages/strahl_data, found relative to libstrahl
as any installed prefix is). No build dependency beyond setuptools, CMake,
Ninja and the Debian packages of tools/setup.sh, so it works offline:

    python3 -m venv --system-site-packages v
    v/bin/pip install --no-build-isolation .
"""
import os
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext


class CMakeBuild(build_ext):
    """Configures, builds and installs the project into the wheel's folder."""

    def build_extension(self, ext):
        dest = os.path.dirname(os.path.abspath(self.get_ext_fullpath(ext.name)))
        prefix = os.path.join(dest, "strahl_data")
        build = os.path.abspath(os.path.join(self.build_temp, "cmake"))
        src = os.path.dirname(os.path.abspath(__file__))
        subprocess.run(["cmake", "-S", src, "-B", build, "-G", "Ninja",
                        "-DCMAKE_BUILD_TYPE=Release", "-DBUILD_TESTING=OFF",
                        f"-DCMAKE_INSTALL_PREFIX={prefix}",
                        f"-DPython3_EXECUTABLE={sys.executable}",
                        f"-DSTRAHL_PYTHON_INSTALL_DIR={dest}"], check=True)
        subprocess.run(["cmake", "--build", build], check=True)
        subprocess.run(["cmake", "--install", build], check=True)


setup(name="strahl", version="0.1.0",
      description="strahl lighting-research framework: render, reference, compare and "
                  "benchmark from Python with numpy arrays",
      ext_modules=[Extension("strahl", sources=[])], cmdclass={"build_ext": CMakeBuild},
      install_requires=["numpy"], zip_safe=False)
