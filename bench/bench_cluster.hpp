// What cellrt_bench and cellrt_scaling do alike in one process and, as cellrt_bench-mpi and
// cellrt_scaling-mpi, over the ranks of an MPI job (apps/cluster.hpp, docs/DISTRIBUTED.md): the same
// program text, linked with the cluster of one process or with that of the MPI ranks. Every process
// parses the same command line and agrees on the scenes; the sweep's runs (a scene each) are shared
// among the processes; the leader prints the tables and writes the results.
#pragma once

#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <new>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "cellrt/error.hpp"
#include "cellrt/loaders.hpp"
#include "cluster.hpp"
#include "core/files.hpp"

namespace cellrt::bench {

namespace cluster = cli::cluster;

// The specs (scene_file) of the scenes among `names` that the leader finds, in their order. Where the
// user named the scenes (`named`, --scenes given), one the leader lacks is an error; of the default
// list, it is skipped with a message, as in one process, and finding none is an error. Every process
// must have the scenes the leader has, at the same path, since any of them may be given a scene's
// runs: a process that lacks one fails the step on all, named.
inline std::vector<std::string> found_scenes(const std::string& scenes_dir, const std::vector<std::string>& names,
                                             bool named) {
    std::vector<std::string> specs;
    std::string here;  // '1' where the scene is found on this process
    for (const std::string& name : names) {
        specs.push_back(scene_file(scenes_dir, name));
        here += scene_found(specs.back()) ? '1' : '0';
    }
    const std::string leaders = cluster::broadcast(here);
    cluster::together([&] {
        for (std::size_t i = 0; i < names.size(); ++i) {
            if (named && leaders[i] == '0') throw Error("--scenes " + names[i] + ": " + specs[i] + " not found");
            if (leaders[i] == '1' && here[i] == '0')
                throw Error("scene " + names[i] + ": " + specs[i] +
                            " not found, which rank 0 has (every rank needs the scenes at the same path)");
        }
        if (leaders.find('1') == std::string::npos)
            throw Error("none of the scenes is in --scenes-dir " + scenes_dir + ": name them with --scenes");
    }, "finding the scenes");
    std::vector<std::string> found;
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (leaders[i] == '1') found.push_back(specs[i]);
        else if (cluster::leader()) print_skipped_scene(names[i], specs[i]);
    }
    return found;
}

// Refuses, before any run, results files (option, path; "" not asked for) that cannot be written, on
// the leader, which writes them: a folder not there, a file the user has without `overwrite`, two
// options naming one file, one naming a file of the scenes `specs` read (scene_files: a view file or
// its mesh, which --overwrite would have replaced). A mistyped path should not cost the sweep, nor a
// sweep a file.
inline void check_results_paths(const std::vector<std::pair<std::string, std::string>>& outputs, bool overwrite,
                                const std::vector<std::string>& specs) {
    cluster::together([&] {
        if (!cluster::leader()) return;
        for (const auto& [option, path] : outputs)
            if (!path.empty()) check_output_file(path, overwrite);
        check_distinct_files(outputs, scene_files(specs));
    }, "checking the results' paths");
}

// `text` (a JSON document, say) written whole as `path` by the leader, once every process has got
// this far; a failure is every process's.
inline void write_results(const std::string& path, const std::string& text, bool overwrite) {
    cluster::together([&] {
        if (cluster::leader()) write_file_atomically(path, text, overwrite);
    }, "writing " + path);
}

// The program's main: joins the job, runs `body` (its exit status), prints the error it ends with as
// "PROGRAM: error: ..." (under MPI once, naming the rank), and returns the status every process agreed
// on (the largest).
inline int main_on_cluster(int argc, char** argv, const char* program, const std::function<int(int, char**)>& body) {
    try {
        cluster::start(argc, argv, program);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: error: %s\n", program, e.what());
        return 1;
    }
    int status = 1;
    try {
        status = body(argc, argv);
    } catch (const std::bad_alloc&) {
        cluster::print_error(Error("out of memory"));
    } catch (const std::exception& e) {
        cluster::print_error(e);
    }
    return cluster::finish(cluster::flushed(status));
}

}  // namespace cellrt::bench
