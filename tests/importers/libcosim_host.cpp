/*
 * A C++ host of the mount FMU on libcosim's C++ API (cosim::execution), the way a
 * host that must survive a failing FMU uses it: the fixed-step algorithm is built
 * with zero worker threads, so every FMU call runs in the host's thread and an FMU
 * error reaches the host as a cosim::error from execution::step().
 *
 * Why zero threads: libcosim's thread pool (src/cosim/utility/thread_pool.hpp,
 * worker_thread) runs tasks without a try block, and fixed_step_algorithm::
 * initialize() submits setup / do_iteration / start_simulation to it without one
 * (only do_step catches); an FMU error during initialization in a worker thread is
 * std::terminate. libcosimc (cosim_execution_create) and so libcosimpy always build
 * the algorithm with the default pool of hardware_concurrency() - 1 threads, and
 * the pool runs tasks inline only when it has no thread. See docs/fmu.md, 7.
 *
 * usage: libcosim_host FMU CASE...   with CASE one of
 *   bad:NAME=VALUE[,NAME=VALUE...]   one instance, axial friction on, the given real
 *                                    start values; one step (initialization + step)
 *   good:N0,KF,X,FREQ,H,CYCLES       one instance, axial friction on, u_axial =
 *                                    X sin(2 pi FREQ t), v_axial = du/dt through the
 *                                    override manipulator, CYCLES periods of steps H
 * The cases run in order in this one process, each in a fresh execution. One JSON
 * object per case on stdout:
 *   {"case": i, "ok": false, "error": "<what()>", "errc": "<code message>"}
 *   {"case": i, "ok": true, "t": [...], "F": [...], "E": [...]}   (good; t_k, outputs
 *                                    after the step from t_k, %.17g)
 * then "DONE". Exit code 0 when every case was reported, 2 on a usage error, 3 when
 * the FMU could not be loaded or instantiated.
 */
#include <cosim/algorithm/fixed_step_algorithm.hpp>
#include <cosim/exception.hpp>
#include <cosim/execution.hpp>
#include <cosim/fmi/fmu.hpp>
#include <cosim/fmi/importer.hpp>
#include <cosim/manipulator/override_manipulator.hpp>
#include <cosim/observer/last_value_observer.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace
{

constexpr unsigned int NO_WORKER_THREADS = 0; // every FMU call in the host's thread

struct Instance
{
    std::unique_ptr<cosim::execution> execution;
    cosim::simulator_index index;
    std::map<std::string, cosim::value_reference> refs;
};

std::string json_string(const std::string& s)
{
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", c);
            out += buf;
        } else {
            out += c;
        }
    }
    return out + "\"";
}

std::string json_array(const std::vector<double>& v)
{
    std::string out = "[";
    char buf[32];
    for (std::size_t i = 0; i < v.size(); ++i) {
        std::snprintf(buf, sizeof buf, "%s%.17g", i ? ", " : "", v[i]);
        out += buf;
    }
    return out + "]";
}

std::vector<std::string> split(const std::string& s, char sep)
{
    std::vector<std::string> parts;
    std::stringstream ss(s);
    for (std::string item; std::getline(ss, item, sep);) parts.push_back(item);
    return parts;
}

cosim::value_reference ref_of(const Instance& inst, const std::string& name)
{
    const auto it = inst.refs.find(name);
    if (it == inst.refs.end()) throw std::invalid_argument("no variable " + name);
    return it->second;
}

/* A fresh execution (zero worker threads) with one instance, axial friction on. */
Instance new_instance(cosim::fmi::importer& importer, const std::string& fmuPath,
                      cosim::duration h)
{
    Instance inst;
    auto algorithm = std::make_shared<cosim::fixed_step_algorithm>(h, NO_WORKER_THREADS);
    inst.execution = std::make_unique<cosim::execution>(cosim::time_point(), algorithm);
    const auto fmu = importer.import(fmuPath);
    for (const auto& v : fmu->model_description()->variables) inst.refs[v.name] = v.reference;
    inst.index = inst.execution->add_slave(fmu->instantiate_slave("mount"), "mount");
    inst.execution->set_boolean_initial_value(inst.index, ref_of(inst, "axial_friction"),
                                              true);
    return inst;
}

void report_error(int k, const std::exception& e, const std::string& errc)
{
    std::printf("{\"case\": %d, \"ok\": false, \"error\": %s, \"errc\": %s}\n", k,
                json_string(e.what()).c_str(), json_string(errc).c_str());
}

void run_bad(int k, cosim::fmi::importer& importer, const std::string& fmu,
             const std::string& spec)
{
    auto inst = new_instance(importer, fmu, std::chrono::microseconds(100));
    for (const auto& item : split(spec, ',')) {
        const auto eq = item.find('=');
        if (eq == std::string::npos) throw std::invalid_argument("bad setting " + item);
        inst.execution->set_real_initial_value(inst.index, ref_of(inst, item.substr(0, eq)),
                                               std::strtod(item.c_str() + eq + 1, nullptr));
    }
    try {
        inst.execution->step();
        std::printf("{\"case\": %d, \"ok\": true}\n", k);
    } catch (const cosim::error& e) {
        report_error(k, e, e.code().message());
    }
}

void run_good(int k, cosim::fmi::importer& importer, const std::string& fmu,
              const std::string& spec)
{
    const auto p = split(spec, ',');
    if (p.size() != 6) throw std::invalid_argument("good needs N0,KF,X,FREQ,H,CYCLES");
    const double n0 = std::stod(p[0]), kf = std::stod(p[1]), x = std::stod(p[2]);
    const double freq = std::stod(p[3]), h = std::stod(p[4]);
    const int cycles = std::stoi(p[5]);
    const auto hNs = std::chrono::nanoseconds(std::llround(h * 1e9));
    auto inst = new_instance(importer, fmu, hNs);
    inst.execution->set_real_initial_value(inst.index, ref_of(inst, "axial_n0"), n0);
    inst.execution->set_real_initial_value(inst.index, ref_of(inst, "axial_kf"), kf);
    auto overrides = std::make_shared<cosim::override_manipulator>();
    auto observer = std::make_shared<cosim::last_value_observer>();
    inst.execution->add_manipulator(overrides);
    inst.execution->add_observer(observer);
    const cosim::value_reference outs[2] = {ref_of(inst, "F_axial"), ref_of(inst, "E_fr_axial")};
    const double omega = 2 * M_PI * freq;
    const long steps = std::lround(cycles / (freq * h)) + 1;
    std::vector<double> t(steps), F(steps), E(steps);
    try {
        for (long i = 0; i < steps; ++i) {
            t[i] = i * h;
            overrides->override_real_variable(inst.index, ref_of(inst, "u_axial"),
                                              x * std::sin(omega * t[i]));
            overrides->override_real_variable(inst.index, ref_of(inst, "v_axial"),
                                              x * omega * std::cos(omega * t[i]));
            inst.execution->step();
            double values[2];
            observer->get_real(inst.index, outs, values);
            F[i] = values[0];
            E[i] = values[1];
        }
    } catch (const cosim::error& e) {
        report_error(k, e, e.code().message());
        return;
    }
    std::printf("{\"case\": %d, \"ok\": true, \"t\": %s, \"F\": %s, \"E\": %s}\n", k,
                json_array(t).c_str(), json_array(F).c_str(), json_array(E).c_str());
}

} // namespace

int main(int argc, char** argv)
{
    if (argc < 3) {
        std::fprintf(stderr, "usage: libcosim_host FMU CASE...\n");
        return 2;
    }
    const std::string fmu = argv[1];
    const auto importer = cosim::fmi::importer::create();
    for (int k = 2; k < argc; ++k) {
        const std::string c = argv[k];
        try {
            if (c.rfind("bad:", 0) == 0) {
                run_bad(k - 2, *importer, fmu, c.substr(4));
            } else if (c.rfind("good:", 0) == 0) {
                run_good(k - 2, *importer, fmu, c.substr(5));
            } else {
                std::fprintf(stderr, "unknown case %s\n", c.c_str());
                return 2;
            }
        } catch (const std::invalid_argument& e) {
            std::fprintf(stderr, "usage error: %s\n", e.what());
            return 2;
        } catch (const cosim::error& e) { // not from a step: loading the FMU failed
            std::fprintf(stderr, "case %d: %s\n", k - 2, e.what());
            return 3;
        }
        std::fflush(stdout);
    }
    std::printf("DONE\n");
    return 0;
}
