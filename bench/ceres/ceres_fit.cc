// SPDX-License-Identifier: MIT
// ceres_fit.cc - the peer a user would pick instead of rcal: the same
// cable-length model fitted by Ceres with automatic differentiation.
//
// Model (as lib/rc_model.h): standard DH, T_i = Rz(q_i + theta_i) Tz(d_i)
// Tx(a_i) Rx(alpha_i); length l = |p(q) - e|, p the flange point, e the
// encoder outlet. Parameters: one block of 27 (a, d, alpha, theta per joint,
// then e), alpha6 held constant as rcal's LM drops it (it never moves the
// flange point). Start: the model file rcal writes after its encoder fit
// (scripts/bench_ceres.sh makes it), so both start from the same point.
// One AutoDiffCostFunction per sample, Levenberg-Marquardt, dense QR, one
// thread, at most 100 iterations, Ceres' default tolerances.
//
// usage: ceres_fit START_MODEL.json DATA.csv [--params] [--target-rms MM]
// prints one line; --params adds the fitted a_mm d_mm alpha_deg theta_deg per
// joint and the encoder outlet; --target-rms the first iteration whose
// training RMS is at or below MM (rcal's final RMS) and Solve's time then.
#include <ceres/ceres.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace {

constexpr int kParams = 27;
constexpr double kDeg = M_PI / 180.0;

struct CableLength {
    CableLength(const double q_rad[6], double len_mm) : len_mm_(len_mm) {
        for (int i = 0; i < 6; ++i) q_[i] = q_rad[i];
    }
    template <typename T>
    bool operator()(const T *const x, T *residual) const {
        // R (3x3 row-major) and o: the running frame.
        T R[9] = {T(1), T(0), T(0), T(0), T(1), T(0), T(0), T(0), T(1)};
        T o[3] = {T(0), T(0), T(0)};
        for (int i = 0; i < 6; ++i) {
            const T a = x[4 * i], d = x[4 * i + 1], al = x[4 * i + 2];
            const T th = T(q_[i]) + x[4 * i + 3];
            const T ct = cos(th), st = sin(th), ca = cos(al), sa = sin(al);
            const T L[9] = {ct, -st * ca, st * sa, st, ct * ca, -ct * sa, T(0), sa, ca};
            const T t[3] = {a * ct, a * st, d};
            T N[9];
            for (int r = 0; r < 3; ++r) {
                for (int k = 0; k < 3; ++k)
                    N[3 * r + k] = R[3 * r] * L[k] + R[3 * r + 1] * L[3 + k] + R[3 * r + 2] * L[6 + k];
                o[r] += R[3 * r] * t[0] + R[3 * r + 1] * t[1] + R[3 * r + 2] * t[2];
            }
            for (int k = 0; k < 9; ++k) R[k] = N[k];
        }
        const T dx = o[0] - x[24], dy = o[1] - x[25], dz = o[2] - x[26];
        residual[0] = sqrt(dx * dx + dy * dy + dz * dz) - T(len_mm_);
        return true;
    }
    double q_[6];
    double len_mm_;
};

// Numbers after each occurrence of key in text (a tiny reader for the
// rcal-model/1 fields used here: a_mm, d_mm, alpha_deg, theta_deg, encoder_mm).
std::vector<double> numbers_after(const std::string &text, const std::string &key, size_t limit_pos) {
    std::vector<double> out;
    size_t pos = 0;
    while ((pos = text.find("\"" + key + "\"", pos)) != std::string::npos && pos < limit_pos) {
        pos = text.find(':', pos) + 1;
        while (text[pos] == ' ' || text[pos] == '[') ++pos;
        out.push_back(std::strtod(text.c_str() + pos, nullptr));
    }
    return out;
}

bool load_start(const char *path, double x[kParams]) {
    std::ifstream f(path);
    if (!f) return false;
    std::stringstream ss;
    ss << f.rdbuf();
    const std::string text = ss.str();
    size_t end = text.find("\"nominal\"");  // the fitted table comes first
    if (end == std::string::npos) end = text.size();
    const auto a = numbers_after(text, "a_mm", end), d = numbers_after(text, "d_mm", end),
               al = numbers_after(text, "alpha_deg", end), th = numbers_after(text, "theta_deg", end);
    if (a.size() != 6 || d.size() != 6 || al.size() != 6 || th.size() != 6) return false;
    for (int i = 0; i < 6; ++i) {
        x[4 * i] = a[i];
        x[4 * i + 1] = d[i];
        x[4 * i + 2] = al[i] * kDeg;
        x[4 * i + 3] = th[i] * kDeg;
    }
    size_t e = text.find("\"encoder_mm\"");
    if (e == std::string::npos) return false;
    const char *p = text.c_str() + text.find('[', e) + 1;
    for (int k = 0; k < 3; ++k) {
        char *next;
        x[24 + k] = std::strtod(p, &next);
        if (next == p) return false;
        p = next + 1;
    }
    return true;
}

// CSV with a header naming q1..q6 (deg) and L (mm).
bool load_data(const char *path, std::vector<double> *q_rad, std::vector<double> *len_mm) {
    std::ifstream f(path);
    std::string line;
    if (!f || !std::getline(f, line)) return false;
    int col_q[6], col_l = -1, c = 0;
    for (int &k : col_q) k = -1;
    std::stringstream hs(line);
    for (std::string name; std::getline(hs, name, ','); ++c) {
        while (!name.empty() && (name.back() == '\r' || name.back() == ' ')) name.pop_back();
        if (name == "L") col_l = c;
        for (int j = 0; j < 6; ++j)
            if (name == "q" + std::to_string(j + 1)) col_q[j] = c;
    }
    if (col_l < 0) return false;
    for (int k : col_q)
        if (k < 0) return false;
    while (std::getline(f, line)) {
        if (line.empty()) continue;
        std::vector<double> v;
        std::stringstream ls(line);
        for (std::string cell; std::getline(ls, cell, ',');) v.push_back(std::strtod(cell.c_str(), nullptr));
        if ((int)v.size() <= col_l) return false;
        for (int j = 0; j < 6; ++j) q_rad->push_back(v[col_q[j]] * kDeg);
        len_mm->push_back(v[col_l]);
    }
    return !len_mm->empty();
}

}  // namespace

int main(int argc, char **argv) {
    bool print_params = false;
    double target_rms = -1.0;
    int bad = argc < 3;
    for (int i = 3; i < argc && !bad; ++i) {
        if (std::strcmp(argv[i], "--params") == 0)
            print_params = true;
        else if (std::strcmp(argv[i], "--target-rms") == 0 && i + 1 < argc)
            target_rms = std::strtod(argv[++i], nullptr);
        else
            bad = 1;
    }
    if (bad) {
        std::fprintf(stderr, "usage: ceres_fit START_MODEL.json DATA.csv [--params] [--target-rms MM]\n");
        return 2;
    }
    double x[kParams];
    std::vector<double> q, len;
    if (!load_start(argv[1], x)) {
        std::fprintf(stderr, "ceres_fit: cannot read the start model %s\n", argv[1]);
        return 1;
    }
    if (!load_data(argv[2], &q, &len)) {
        std::fprintf(stderr, "ceres_fit: cannot read the data %s\n", argv[2]);
        return 1;
    }
    ceres::Problem problem;
    for (size_t i = 0; i < len.size(); ++i)
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<CableLength, 1, kParams>(
                                     new CableLength(&q[6 * i], len[i])),
                                 nullptr, x);
    problem.SetManifold(x, new ceres::SubsetManifold(kParams, {4 * 5 + 2}));  // alpha6
    ceres::Solver::Options opt;
    opt.linear_solver_type = ceres::DENSE_QR;
    opt.max_num_iterations = 100;
    opt.num_threads = 1;
    opt.logging_type = ceres::SILENT;
    ceres::Solver::Summary sum;
    ceres::Solve(opt, &problem, &sum);
    const double n = static_cast<double>(len.size());
    std::printf("ceres: %zu samples, %d iterations, rms %.6f -> %.6f mm, %.2f ms in Solve, %s\n", len.size(),
                static_cast<int>(sum.iterations.size()) - 1, std::sqrt(2.0 * sum.initial_cost / n),
                std::sqrt(2.0 * sum.final_cost / n), sum.total_time_in_seconds * 1e3,
                ceres::TerminationTypeToString(sum.termination_type));
    if (target_rms > 0.0) {
        const ceres::IterationSummary *hit = nullptr;
        for (const auto &it : sum.iterations)
            if (std::sqrt(2.0 * it.cost / n) <= target_rms) {
                hit = &it;
                break;
            }
        if (hit)
            std::printf("  RMS <= %.6f mm first at iteration %d, %.2f ms into Solve\n", target_rms, hit->iteration,
                        hit->cumulative_time_in_seconds * 1e3);
        else
            std::printf("  RMS <= %.6f mm never reached\n", target_rms);
    }
    if (print_params) {
        for (int i = 0; i < 6; ++i)
            std::printf("  joint %d: a %.4f mm, d %.4f mm, alpha %.5f deg, theta %.5f deg\n", i + 1, x[4 * i],
                        x[4 * i + 1], x[4 * i + 2] / kDeg, x[4 * i + 3] / kDeg);
        std::printf("  encoder e = (%.4f, %.4f, %.4f) mm\n", x[24], x[25], x[26]);
    }
    return sum.IsSolutionUsable() ? 0 : 1;
}
