"""
The same fit from C++
=====================

The core is a C++17 library with an installable CMake package: ``find_package(lptv)`` and the
target ``lptv::core``. This example writes a small C++ program, builds it with CMake against
the installed package and runs it on measurements that Python wrote; the C++ estimate is the
one ``lptv.identify`` returns, since the Python package calls the same core.

``make docs`` installs the C++ package into ``build/install`` first (as ``make test`` does for
``tests/cmake_consumer``) and names it in ``LPTV_PREFIX``; by hand: ``cmake -S . -B build/cpp``
and ``cmake --install build/cpp --prefix PREFIX``.
"""
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

import lptv
from lptv.examples import noisy_periods, paper_model, paper_multisine

prefix = Path(os.environ.get("LPTV_PREFIX", "build/install")).resolve()
assert (prefix / "lib" / "cmake" / "lptv").is_dir() or list(prefix.glob("lib*/cmake/lptv")), \
    f"no installed lptv CMake package under {prefix} (set LPTV_PREFIX)"

# %%
# The measurements: the paper's example, 4 periods, written as raw doubles (P, N, u, y)
model = paper_model()
ms = paper_multisine(seed=1)
y0 = lptv.time_signal(lptv.simulate(model, ms.spectrum), ms.n_samples)
u, y = noisy_periods(ms.signal, y0, 4, 50, 30, seed=2)
work = Path(tempfile.mkdtemp())
np.concatenate([[u.shape[0], u.shape[1]], u.ravel(), y.ravel()]).tofile(work / "periods.bin")

# %%
# The C++ program and its CMakeLists.txt
# --------------------------------------
cpp = r"""
#include <lptv/estimators.hpp>
#include <lptv/noise.hpp>

#include <cstdio>
#include <fstream>
#include <vector>

int main(int argc, char** argv) {
  std::ifstream f(argv[1], std::ios::binary);
  double size[2];
  f.read(reinterpret_cast<char*>(size), sizeof size);
  const int P = static_cast<int>(size[0]), N = static_cast<int>(size[1]);
  // row-major (P, N) from NumPy into Eigen's column-major matrices
  std::vector<double> buf(2 * static_cast<size_t>(P) * N);
  f.read(reinterpret_cast<char*>(buf.data()), buf.size() * sizeof(double));
  Eigen::MatrixXd u(P, N), y(P, N);
  for (int p = 0; p < P; ++p)
    for (int n = 0; n < N; ++n) u(p, n) = buf[p * N + n], y(p, n) = buf[(P + p) * N + n];

  const lptv::FrequencyData d = lptv::frequency_data_from_periods(u, y);
  lptv::Structure s;                    // na = 2, nb = 1, 3 harmonics on every coefficient
  s.na = 2; s.nb = 1; s.ka = {3, 3, 3}; s.kb = {3, 3}; s.w0 = 0.04;
  lptv::IdentifyOptions opt;
  opt.method = lptv::Method::SML;
  for (int l = 1; l < 244; ++l) opt.rows.push_back(l);
  const lptv::Identification id = lptv::identify(d, s, opt);
  std::printf("converged %d after %d iterations\n", id.converged ? 1 : 0, id.iterations);
  for (int i = 0; i < id.eta.size(); ++i)
    std::printf("%s %.17g %.17g\n", id.eta_names[i].c_str(), id.eta[i], std::sqrt(id.covariance(i, i)));
}
"""
cmake = """
cmake_minimum_required(VERSION 3.18)
project(lptv_example CXX)
find_package(lptv 0.1 REQUIRED)
add_executable(fit main.cpp)
target_link_libraries(fit PRIVATE lptv::core)
"""
(work / "main.cpp").write_text(cpp)
(work / "CMakeLists.txt").write_text(cmake)

# %%
# Build and run
# -------------
cmake_exe = shutil.which("cmake")
subprocess.run([cmake_exe, "-S", work, "-B", work / "build", "-DCMAKE_BUILD_TYPE=Release",
                f"-DCMAKE_PREFIX_PATH={prefix}"], check=True, capture_output=True)
subprocess.run([cmake_exe, "--build", work / "build"], check=True, capture_output=True)
out = subprocess.run([work / "build" / "fit", work / "periods.bin"], check=True, capture_output=True,
                     text=True).stdout
lines = out.splitlines()
print("\n".join(lines[:6]), "\n...")

# %%
# The same fit in Python gives the same numbers. The C++ ``lptv::identify`` weighs by each line's
# own sample (co)variances; Python's default (``noise="auto"``) may moderate them across lines,
# so the same route is asked for.
res = lptv.identify(u, y, na=2, nb=1, ka=3, kb=3, w0=0.04, lines=range(1, 244), method="sml",
                    noise="sample")
eta_cpp = np.array([float(line.split()[1]) for line in lines[1:]])
print("parameters:", eta_cpp.size, " largest difference C++ - Python:", np.abs(eta_cpp - res.eta).max())
assert np.allclose(eta_cpp, res.eta, rtol=1e-9, atol=1e-12)
shutil.rmtree(work)

import matplotlib.pyplot as plt

fig, ax = plt.subplots()
ax.plot(res.eta, eta_cpp, "o", mfc="none")
ax.plot([res.eta.min(), res.eta.max()], [res.eta.min(), res.eta.max()], "k-", lw=0.6)
ax.set_xlabel("parameter from lptv.identify (Python)")
ax.set_ylabel("parameter from lptv::identify (C++)")
