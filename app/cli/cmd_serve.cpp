// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot serve`: runs a study's listening test online (issue 14). Participants open their
// secret link (`underfoot study invite`); the page drives the same experiment::Session as the
// terminal and the console, and every answer is a durable transaction in the same study file.
// Binds 127.0.0.1 unless told otherwise; Ctrl+C or SIGTERM stops cleanly (open sessions are
// closed as interrupted and resume at the first unanswered trial).
#include "app/cli/CommandRegistry.h"
#include "app/web/Server.h"
#include "app/web/WebStudy.h"

#include <fmt/core.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <pthread.h>
#include <thread>

namespace underfoot::cli::serve_command {
namespace {

using underfoot::cli::UserError;
namespace web = underfoot::web;

struct Options {
    std::string study;
    std::string clips;
    std::string bind = "127.0.0.1";
    int port = 8080;
    std::string screening = "flag";
    double rate = 20.0;
    std::size_t maxBody = 16 * 1024;
};

Options& opts() {
    static Options o;
    return o;
}

int serve(const Options& o) {
    // SIGINT / SIGTERM are taken by one waiting thread (no work in a signal handler); blocked
    // before the server's threads start so that every thread inherits the mask.
    sigset_t stopSignals;
    sigemptyset(&stopSignals);
    sigaddset(&stopSignals, SIGINT);
    sigaddset(&stopSignals, SIGTERM);
    sigaddset(&stopSignals, SIGUSR1); // internal: wakes the waiting thread after a server error
    pthread_sigmask(SIG_BLOCK, &stopSignals, nullptr);

    web::WebOptions wo;
    wo.clipsDir = o.clips;
    wo.screeningFailure =
        o.screening == "end" ? web::ScreeningFailure::End : web::ScreeningFailure::Flag;
    std::unique_ptr<web::WebStudy> study;
    try {
        study = std::make_unique<web::WebStudy>(o.study, wo);
    } catch (const std::exception& e) {
        throw UserError(fmt::format("serve: {}", e.what()));
    }
    web::ServerOptions so;
    so.bind = o.bind;
    so.port = o.port;
    so.ratePerSecond = o.rate;
    so.burst = o.rate * 3;
    so.maxBodyBytes = o.maxBody;
    web::WebServer server(*study, so);
    int port = 0;
    try {
        port = server.bind();
    } catch (const std::exception& e) {
        throw UserError(fmt::format("serve: {}", e.what()));
    }
    const std::string host = o.bind.find(':') != std::string::npos ? "[" + o.bind + "]" : o.bind;
    fmt::print("underfoot serve: study {} listening on http://{}:{}/ (participant links: "
               "http://{}:{}/p#TOKEN); Ctrl+C stops\n",
               o.study, host, port, host, port);
    if (o.bind != "127.0.0.1" && o.bind != "::1" && o.bind != "localhost")
        fmt::print("underfoot serve: bound to {}: put a TLS reverse proxy in front (docs/web.md)\n",
                   o.bind);
    std::fflush(stdout);

    std::atomic<int> caught{0};
    std::thread waiter([&] {
        int signal = 0;
        sigwait(&stopSignals, &signal);
        caught = signal;
        server.stop();
    });
    server.run();
    if (caught == 0) pthread_kill(waiter.native_handle(), SIGUSR1); // run() ended by itself
    waiter.join();
    const int open = study->openSessions();
    study->stop();
    const auto c = server.counters();
    fmt::print("underfoot serve: stopped ({}); {} open sessions closed as interrupted; {} "
               "requests, {} refused, {} rate-limited\n",
               caught == SIGTERM  ? "SIGTERM"
               : caught == SIGINT ? "SIGINT"
                                  : "server ended",
               open, c.requests, c.refused, c.rateLimited);
    std::fflush(stdout);
    return 0;
}

const underfoot::cli::CommandRegistrar registrar{
    "serve", [](CLI::App& app, int& exitCode) {
        Options& o = opts();
        auto* cmd = app.add_subcommand(
            "serve", "Run a study's listening test online: participants open their links from "
                     "`underfoot study invite` in a browser");
        cmd->add_option("--study", o.study, "study file (.db)")->required();
        cmd->add_option("--clips", o.clips, "folder of the clips (`underfoot clips -o DIR`)")
            ->required();
        cmd->add_option("--port", o.port, "TCP port (0: any free port)")
            ->check(CLI::Range(0, 65535));
        cmd->add_option("--bind", o.bind,
                        "address to listen on (default 127.0.0.1; use a TLS reverse proxy for "
                        "anything else)");
        cmd->add_option("--screening-failure", o.screening,
                        "a failed headphone screening 'flag's the participant (stored, the test "
                        "goes on) or 'end's the session (participant dropped)")
            ->check(CLI::IsMember({"flag", "end"}));
        cmd->add_option("--rate", o.rate, "requests per second allowed per link (burst: 3x)")
            ->check(CLI::Range(1.0, 10000.0));
        cmd->add_option("--max-body", o.maxBody, "largest request body in bytes")
            ->check(CLI::Range(1024, 1024 * 1024));
        cmd->callback([&exitCode, &o] { exitCode = serve(o); });
    }};

} // namespace
} // namespace underfoot::cli::serve_command
