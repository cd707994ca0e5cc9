// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Shared helpers of the web tests: a study with invitations and clips in a temporary folder,
// an in-process server on a loopback port, and a small JSON client over Boost.Beast that can
// connect from any loopback address (127.0.0.0/8), so that tests can play many clients.
#include "app/web/Server.h"
#include "app/web/WebStudy.h"
#include "experiment/Clips.h"
#include "experiment/Invitations.h"
#include "experiment/Protocol.h"
#include "experiment/Store.h"

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/http.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

namespace underfoot::web::test {

namespace fs = std::filesystem;
using nlohmann::json;

class TempDir {
  public:
    TempDir() {
        static std::atomic<int> counter{0};
        path_ = fs::temp_directory_path() /
                ("underfoot-web-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
        fs::remove_all(path_);
        fs::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    std::string file(const std::string& name) const { return (path_ / name).string(); }

  private:
    fs::path path_;
};

/// An identification + rating listening test: practice, 6 main trials, a break after 3,
/// a required participant field, a comment. `extra` is appended to [clips].
inline std::string webProtocol(const std::string& clipsExtra = "replay = true\n") {
    return "[protocol]\nid = \"web_ident\"\nversion = 1\n"
           "title = \"Web <b>identification</b> & \\\"escape\\\"\"\n"
           "description = \"Listen & identify <script>alert(1)</script>.\"\n"
           "[design]\ntype = \"within\"\n"
           "[input]\ntype = \"walker\"\n"
           "[clips]\nseconds = 1\nseed = 7\n" +
           clipsExtra +
           "[[stimuli]]\nid = \"WD\"\nsurface = \"wood\"\n"
           "[[stimuli]]\nid = \"GL\"\nsurface = \"gravel\"\n"
           "[[stimuli]]\nid = \"MT\"\nsurface = \"metal\"\n"
           "[ordering]\nrepetitions = 2\npractice = [\"WD\"]\nbreak_every = 3\n"
           "[questions]\ncomment = true\n[questions.surface]\nprompt = \"Which surface?\"\n"
           "options = [\"wood\", \"gravel\", \"metal\"]\n"
           "[[questions.scales]]\nid = \"realism\"\nprompt = \"How realistic?\"\nmin = 1\nmax = 7\n"
           "anchors = { 1 = \"not at all\", 7 = \"very\" }\n"
           "[[participant_fields]]\nid = \"listening_device\"\nlabel = \"Listening device\"\n"
           "options = [\"laptop_speakers\", \"headphones\"]\n";
}

/// A valid 16-bit mono WAV of `frames` samples of a quiet tone.
inline void writeWav(const std::string& path, int frames = 4800, int rate = 48000) {
    std::ofstream out(path, std::ios::binary);
    auto u32 = [&](std::uint32_t v) { out.write(reinterpret_cast<const char*>(&v), 4); };
    auto u16 = [&](std::uint16_t v) { out.write(reinterpret_cast<const char*>(&v), 2); };
    out.write("RIFF", 4);
    u32(36 + static_cast<std::uint32_t>(frames) * 2);
    out.write("WAVEfmt ", 8);
    u32(16);
    u16(1);
    u16(1);
    u32(static_cast<std::uint32_t>(rate));
    u32(static_cast<std::uint32_t>(rate) * 2);
    u16(2);
    u16(16);
    out.write("data", 4);
    u32(static_cast<std::uint32_t>(frames) * 2);
    for (int i = 0; i < frames; ++i)
        u16(static_cast<std::uint16_t>(static_cast<std::int16_t>((i % 48) < 24 ? 800 : -800)));
}

/// A study file with `invites` links and a clips folder holding every clip.
struct StudyFixture {
    TempDir dir;
    std::string study = dir.file("online.db");
    std::string clips = dir.file("clips");
    std::vector<experiment::NewInvitation> links;

    explicit StudyFixture(int invites, const std::string& protocolText = webProtocol())
        : StudyFixture(invites, experiment::parseProtocol(protocolText, "web.toml")) {}

    StudyFixture(int invites, const experiment::Protocol& p) {
        experiment::StudyStore store =
            experiment::StudyStore::create(study, p, {"WEB", "web", 4, "test"});
        experiment::Invitations inv(store);
        links = inv.create(store, invites, std::nullopt);
        fs::create_directories(clips);
        std::vector<experiment::ClipRecord> manifest;
        for (const auto& s : p.stimuli) {
            const std::string path = experiment::clipPath(s, clips);
            fs::create_directories(fs::path(path).parent_path()); // lab clips in sub-folders
            writeWav(path);
            // The manifest `underfoot clips` writes (a test tone stands for the render): the
            // server serves and stores only clips that match it.
            experiment::ClipRecord r;
            r.stimulusId = s.id;
            r.file = fs::path(path).filename().string();
            r.source = s.clip ? experiment::ClipSource::Lab : experiment::ClipSource::Footsteps;
            r.seed = experiment::clipSeed(p, s);
            r.sampleRateHz = 48000;
            r.frames = 4800;
            r.seconds = 0.1;
            r.sha256 = experiment::fileSha256(path);
            manifest.push_back(r);
        }
        experiment::writeClipManifest(clips, manifest);
    }
};

/// The server's options in tests: headphone-check answers accepted at once after their tones
/// (the default waits the tones' 4 s; WebScreening tests that rule).
inline WebOptions testOptions() {
    WebOptions wo;
    wo.screeningMinResponseS = 0.0;
    return wo;
}
/// The same for `underfoot serve` processes.
inline const std::vector<std::string> kServeTestArgs{"--screening-min-response", "0"};

/// WebStudy + WebServer on a free loopback port, served by a thread.
struct InProcessServer {
    std::unique_ptr<WebStudy> study;
    std::unique_ptr<WebServer> server;
    std::thread thread;
    int port = 0;

    InProcessServer(const StudyFixture& f, ServerOptions so = {}, WebOptions wo = testOptions())
        : InProcessServer(f.study, f.clips, so, wo) {}
    InProcessServer(const std::string& studyPath, const std::string& clipsDir, ServerOptions so,
                    WebOptions wo) {
        wo.clipsDir = clipsDir;
        study = std::make_unique<WebStudy>(studyPath, wo);
        so.port = 0;
        server = std::make_unique<WebServer>(*study, so);
        port = server->bind();
        thread = std::thread([this] { server->run(); });
    }
    ~InProcessServer() {
        server->stop();
        thread.join();
        study->stop();
    }
};

/// One HTTP answer: status and parsed JSON (null when not JSON).
struct Reply {
    /// 0: no answer (no connection, closed, or no answer within the time allowed).
    int status = 0;
    json body;
    std::string raw;
    std::map<std::string, std::string> headers;
};

using Headers = std::vector<std::pair<std::string, std::string>>;

/// One request on a fresh connection from `source` (a loopback address) to 127.0.0.1:`port`;
/// the request is written while the answer is read, so an answer sent before the server read
/// the whole body is seen.
inline Reply exchange(int port, const std::string& method, const std::string& path,
                      const Headers& headers, const std::string& body,
                      const std::string& source = "127.0.0.1", double timeoutS = 10.0) {
    namespace asio = boost::asio;
    namespace http = boost::beast::http;
    using tcp = asio::ip::tcp;
    asio::io_context ioc;
    tcp::socket socket(ioc);
    boost::system::error_code ec;
    socket.open(tcp::v4(), ec);
    if (!ec) socket.bind(tcp::endpoint(asio::ip::make_address(source), 0), ec);
    if (!ec) socket.set_option(tcp::no_delay(true), ec);
    Reply out;
    if (ec) return out;
    http::request<http::string_body> req;
    const http::verb verb = http::string_to_verb(method);
    if (verb == http::verb::unknown)
        req.method_string(method);
    else
        req.method(verb);
    req.target(path);
    req.version(11);
    req.set(http::field::host, "127.0.0.1");
    for (const auto& [name, value] : headers) req.set(name, value);
    if (method == "POST" || !body.empty()) {
        req.body() = body;
        req.prepare_payload();
    }
    boost::beast::flat_buffer buffer;
    http::response_parser<http::string_body> parser;
    parser.body_limit(std::uint64_t{1} << 30);
    if (method == "HEAD") parser.skip(true);
    bool done = false;
    socket.async_connect(
        tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)),
        [&](boost::system::error_code e) {
            if (e) return;
            http::async_write(socket, req, [](boost::system::error_code, std::size_t) {});
            http::async_read(socket, buffer, parser,
                             [&](boost::system::error_code r, std::size_t) { done = !r; });
        });
    ioc.run_for(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(timeoutS)));
    if (!done) return out;
    const auto& res = parser.get();
    out.status = static_cast<int>(res.result_int());
    out.raw = res.body();
    for (const auto& f : res) out.headers[std::string(f.name_string())] = std::string(f.value());
    out.body = json::parse(out.raw, nullptr, false);
    if (out.body.is_discarded()) out.body = nullptr;
    return out;
}

/// A participant's client (a fresh connection per call), from a chosen loopback address.
class ApiClient {
  public:
    ApiClient(int port, std::string token, std::string source = "127.0.0.1")
        : port_(port), token_(std::move(token)), source_(std::move(source)) {}
    void setToken(std::string token) { token_ = std::move(token); }
    void setPort(int port) { port_ = port; }

    Reply get(const std::string& path) const {
        return exchange(port_, "GET", path, headers(), "", source_);
    }
    Reply post(const std::string& path, const json& body) const {
        return postRaw(path, body.dump());
    }
    Reply postRaw(const std::string& path, const std::string& body) const {
        Headers h = headers();
        h.emplace_back("Content-Type", "application/json");
        return exchange(port_, "POST", path, h, body, source_);
    }

  private:
    Headers headers() const {
        Headers h{{"User-Agent", "underfoot-web-test/1"}};
        if (!token_.empty()) h.emplace_back("Authorization", "Bearer " + token_);
        return h;
    }
    int port_;
    std::string token_;
    std::string source_;
};

/// The loopback address of simulated client `i` (127.0.1.1, 127.0.1.2, ...; all reach the
/// server over the loopback interface, each seen as its own address).
inline std::string clientAddress(int i) {
    return "127.0." + std::to_string(1 + i / 250) + "." + std::to_string(1 + i % 250);
}

/// The interval (1, 2 or 3) a listener names the quietest in a headphone-check triplet's WAV
/// as served (16-bit stereo PCM, three tones in equal thirds): with headphones each ear hears
/// its own channel (the left one's peaks are compared); over loudspeakers the ears hear the
/// sum of both channels, in which the antiphase tone cancels. Throws when it is not such a WAV.
inline int quietestHeard(const std::string& wav, bool loudspeakers = false) {
    if (wav.size() < 44 || wav.compare(0, 4, "RIFF") != 0 || wav.compare(36, 4, "data") != 0)
        throw std::runtime_error("not a WAV file: " + wav.substr(0, 200));
    const auto* pcm = reinterpret_cast<const unsigned char*>(wav.data() + 44);
    const std::size_t frames = (wav.size() - 44) / 4;
    auto sample = [&](std::size_t i) {
        return static_cast<int>(static_cast<std::int16_t>(pcm[2 * i] | (pcm[2 * i + 1] << 8)));
    };
    int best = 0;
    int quietest = 0;
    for (int k = 0; k < 3; ++k) {
        int peak = 0;
        for (std::size_t f = k * frames / 3; f < (k + 1) * frames / 3; ++f) {
            const int v = loudspeakers ? sample(2 * f) + sample(2 * f + 1) : sample(2 * f);
            peak = std::max(peak, std::abs(v));
        }
        if (k == 0 || peak < best) {
            best = peak;
            quietest = k + 1;
        }
    }
    return quietest;
}

/// How a simulated participant does the headphone check.
enum class Listener { Headphones, Loudspeakers, Guess1 };

/// The headphone check through the API as a listener does it: start, then per triplet its
/// tones and the interval heard quietest (Guess1: always 1, without fetching the tones).
/// Returns the last reply (the state after the verdict when every step was accepted).
inline Reply doScreening(const ApiClient& c, Listener who = Listener::Headphones) {
    // From the triplet the server waits for: a retry after a lost reply or a restart goes on.
    Reply r = c.post("/api/screening/start", json::object());
    for (int guard = 0; guard < 12 && r.status == 200 && r.body.value("phase", "") == "screening";
         ++guard) {
        const int k = r.body.at("check").at("next");
        int choice = 1;
        if (who != Listener::Guess1) {
            const Reply tones = c.get("/api/screening/tones/" + std::to_string(k));
            if (tones.status != 200) return tones;
            choice = quietestHeard(tones.raw, who == Listener::Loudspeakers);
        }
        r = c.post("/api/screening", {{"triplet", k}, {"choice", choice}});
    }
    return r;
}

/// The consent of a participant of webProtocol() (its one required field answered).
inline Reply consent(const ApiClient& c) {
    return c.post("/api/consent",
                  {{"consent", true}, {"fields", {{"listening_device", "headphones"}}}});
}

/// Consent + screening; returns the state of the first trial.
inline json startParticipant(const ApiClient& c) {
    Reply r = consent(c);
    EXPECT_EQ(r.status, 200) << r.raw;
    EXPECT_EQ(r.body["phase"], "screening");
    r = c.post("/api/client", {{"sampleRate", 48000}});
    EXPECT_EQ(r.status, 200) << r.raw;
    r = doScreening(c);
    EXPECT_EQ(r.status, 200) << r.raw;
    EXPECT_EQ(r.body["screening"]["passed"], true) << r.raw;
    return r.body;
}

/// The answer a simulated participant gives to the trial in `state` (valid for webProtocol()).
inline json validAnswer(const json& state, const std::string& attempt) {
    const json& t = state.at("trial");
    json a{{"trial", t.at("index")}, {"attempt", attempt}, {"clientMs", 1234.5}};
    if (t.contains("surface")) a["answer"] = t["surface"]["options"][0]["id"];
    if (t.contains("soundscape")) a["soundscape"] = t["soundscape"]["options"][0]["id"];
    json ratings = json::object();
    for (const auto& s : t.at("scales")) ratings[s.at("id").get<std::string>()] = s.at("max");
    a["ratings"] = ratings;
    return a;
}

} // namespace underfoot::web::test
