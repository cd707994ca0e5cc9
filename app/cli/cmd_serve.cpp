// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot serve`: runs a study's listening test online. Participants open their
// secret link (`underfoot study invite`); the page drives the same experiment::Session as the
// terminal and the console, and every answer is a durable transaction in the same study file.
// Binds 127.0.0.1 unless told otherwise; Ctrl+C or SIGTERM stops cleanly (open sessions are
// closed as interrupted and resume at the first unanswered trial). The limits and options are
// listed in docs/reference/web-server.md.
#include "app/cli/CommandRegistry.h"
#include "app/web/Server.h"
#include "app/web/WebStudy.h"

#include <fmt/core.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <pthread.h>
#include <thread>
#include <vector>

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
    double screeningMinResponse = underfoot::experiment::HeadphoneCheck::tripletSeconds();
    double rate = 20.0;
    std::size_t maxBody = 16 * 1024;
    std::vector<std::string> trustedProxies;
    double requestTimeout = 10.0;
    double idleTimeout = 5.0;
    std::size_t maxConnections = 1024;
    std::size_t maxConnectionsPerAddress = 64;
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
    wo.screeningMinResponseS = o.screeningMinResponse;
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
    so.trustedProxies = o.trustedProxies;
    so.requestTimeoutS = o.requestTimeout;
    so.idleTimeoutS = o.idleTimeout;
    so.maxConnections = o.maxConnections;
    so.maxConnectionsPerAddress = o.maxConnectionsPerAddress;
    std::unique_ptr<web::WebServer> serverPtr;
    int port = 0;
    try {
        serverPtr = std::make_unique<web::WebServer>(*study, so);
        port = serverPtr->bind();
    } catch (const std::exception& e) {
        throw UserError(fmt::format("serve: {}", e.what()));
    }
    web::WebServer& server = *serverPtr;
    const std::string host = o.bind.find(':') != std::string::npos ? "[" + o.bind + "]" : o.bind;
    fmt::print("underfoot serve: study {} listening on http://{}:{}/ (participant links: "
               "http://{}:{}/p#TOKEN); Ctrl+C stops\n",
               o.study, host, port, host, port);
    if (o.bind != "127.0.0.1" && o.bind != "::1" && o.bind != "localhost")
        fmt::print("underfoot serve: bound to {}: put a TLS reverse proxy in front "
                   "(docs/howto/online-test.md)\n",
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
               "requests, {} refused, {} rate-limited, {} timed out; {} connections refused\n",
               caught == SIGTERM  ? "SIGTERM"
               : caught == SIGINT ? "SIGINT"
                                  : "server ended",
               open, c.requests, c.refused, c.rateLimited, c.timedOut, c.connectionsRefused);
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
        cmd->add_option("--screening-min-response", o.screeningMinResponse,
                        "seconds after a headphone-check triplet's tones are served before its "
                        "answer is accepted (default: the tones' length, 4; lower only in tests)")
            ->check(CLI::Range(0.0, 60.0));
        cmd->add_option("--rate", o.rate,
                        "API requests per second per invitation, and per client address for "
                        "requests without a real invitation's token (burst: 3x; the page and "
                        "its files are not limited)")
            ->check(CLI::Range(1.0, 10000.0));
        cmd->add_option("--max-body", o.maxBody,
                        "largest request body in bytes (chunked bodies too; larger: 413)")
            ->check(CLI::Range(1024, 1024 * 1024));
        cmd->add_option("--trusted-proxy", o.trustedProxies,
                        "address of a reverse proxy whose X-Forwarded-For names the client "
                        "(repeatable; e.g. 127.0.0.1 for a proxy on this machine)");
        cmd->add_option("--request-timeout", o.requestTimeout,
                        "seconds within which a request's header and body must arrive")
            ->check(CLI::Range(1.0, 300.0));
        cmd->add_option("--idle-timeout", o.idleTimeout,
                        "seconds a connection may wait without a request in progress")
            ->check(CLI::Range(1.0, 300.0));
        cmd->add_option("--max-connections", o.maxConnections, "open connections in all")
            ->check(CLI::Range(16, 100000));
        cmd->add_option("--max-connections-per-address", o.maxConnectionsPerAddress,
                        "open connections from one address (trusted proxies excepted)")
            ->check(CLI::Range(1, 100000));
        cmd->callback([&exitCode, &o] { exitCode = serve(o); });
    }};

} // namespace
} // namespace underfoot::cli::serve_command
