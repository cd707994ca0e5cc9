#!/usr/bin/env python3
# Writes the seed corpus of fuzz_web_request (tests/fuzz/corpus/web_request/): the requests of
# tests/web/test_web_api.cpp and test_web_attacks.cpp (the participant flow, retries, bad
# tokens, another participant's trial, invalid answers, out-of-range numbers, traversal paths,
# oversized and non-JSON bodies, conflicting framing, many header fields, X-Forwarded-For), in
# the target's format: requests separated by lines "%%", @TOKEN0@/@TOKEN1@ for the two link
# tokens.
import json, os

d = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", "web_request")
os.makedirs(d, exist_ok=True)
for f in os.listdir(d):
    os.remove(os.path.join(d, f))

def req(method, path, body=None, token="@TOKEN0@", extra=()):
    lines = [f"{method} {path} HTTP/1.1", "Host: 127.0.0.1", "User-Agent: underfoot-web-test/1"]
    if token is not None:
        lines.append(f"Authorization: Bearer {token}")
    lines += list(extra)
    if body is not None:
        lines.append("Content-Type: application/json")
    text = "\r\n".join(lines) + "\r\n\r\n"
    if body is not None:
        text += body if isinstance(body, str) else json.dumps(body)
    return text

def seq(*requests):
    return "\n%%\n".join(requests)

consent = req("POST", "/api/consent", {"consent": True, "fields": {"listening_device": "headphones"}})
client = req("POST", "/api/client", {"sampleRate": 48000})
screen = req("POST", "/api/screening", {"correct": 6, "total": 6})
start = [consent, client, screen, req("GET", "/api/state")]

def answer(index, attempt, **over):
    a = {"trial": index, "attempt": attempt, "clientMs": 1234.5, "answer": "wood",
         "ratings": {"realism": 7}}
    a.update(over)
    return req("POST", "/api/answer", a)

def present(trial, **over):
    b = {"trial": trial}
    b.update(over)
    return req("POST", "/api/present", b)

seeds = {
    "flow_first_trials": seq(*start, present(0), req("GET", "/api/clip/0"), answer(0, "a0"),
                             present(1), answer(1, "a1", answer="gravel", comment="ok"),
                             req("POST", "/api/break", {}), present(2), answer(2, "a2")),
    "retried_answer": seq(*start, present(0), answer(0, "x1"), answer(0, "x1"),
                          answer(0, "x2", answer="gravel")),
    "bad_tokens": seq(req("GET", "/api/state", token="nonsense"),
                      req("POST", "/api/consent", {"consent": True}, token=""),
                      req("GET", "/api/clip/0", token="A" * 43), req("GET", "/api/state", token=None)),
    "other_participant": seq(*start, present(0, participant="P002"),
                             req("POST", "/api/answer", {"trial": 0, "attempt": "b1",
                                 "answer": "wood", "ratings": {"realism": 3}}, token="@TOKEN1@"),
                             present(3), req("GET", "/api/clip/5")),
    "invalid_answers": seq(*start, present(0), answer(0, "i1", answer="snow"),
                           answer(0, "i2", answer=""), answer(0, "i3", ratings={"realism": 8}),
                           answer(0, "i4", ratings={}), answer(0, "i5", ratings={"realism": 3.5}),
                           answer(0, "i6", ratings={"realism": "7"}),
                           answer(0, "i7", comment="x" * 2001), answer(0, "i8", clientMs=-1),
                           answer(0, "i9", trial="0"), answer(0, "bad id!"),
                           req("POST", "/api/answer", "{not json"),
                           req("POST", "/api/answer", "[1,2]")),
    "consent_fields": seq(req("POST", "/api/consent", {"consent": True}),
                          req("POST", "/api/consent", {"consent": False}),
                          req("POST", "/api/consent", {"consent": True,
                              "fields": {"listening_device": "radio"}}),
                          req("POST", "/api/client", {"sampleRate": -5})),
    "failed_screening": seq(consent, client, req("POST", "/api/screening", {"correct": 2, "total": 6}),
                            req("GET", "/api/state")),
    "replays": seq(*start, present(0, attempt="p1"), present(0, attempt="p1"),
                   present(0, attempt="p2"), present(0, attempt="p3")),
    "paths": seq(*[req("GET", p) for p in [
        "/assets/../../etc/passwd", "/assets/..%2F..%2Fetc%2Fpasswd", "/assets/%2e%2e/secret.txt",
        "/assets//etc/passwd", "/assets/", "/api/clip/../../secret.txt", "/api/clip/-1",
        "/api/clip/999999", "/clips/WD.wav", "/assets/index.html", "/assets/app.js", "/p", "/"]]),
    "methods": seq(req("PUT", "/api/answer", {}), req("DELETE", "/api/state"),
                   req("HEAD", "/p"), req("POST", "/api/state", {}), req("GET", "/api/answer")),
    "oversized": req("POST", "/api/consent", " " * 20000),
    "numbers": seq(*start, present(0), answer(0, "n1", trial=2**32), answer(0, "n2", trial=2**31),
                   answer(0, "n3", trial=-2**31 - 1), answer(0, "n4", ratings={"realism": 2**32 + 7}),
                   answer(0, "n5", trial=2**64 - 1), req("POST", "/api/answer", '{"trial": 1e400}'),
                   req("POST", "/api/answer", '{"x": [[[[[[[[[1]]]]]]]]]}'),
                   present(2**32), req("GET", "/api/clip/4294967296")),
    "framing": seq(req("POST", "/api/state", "0\r\n\r\n",
                       extra=["Content-Length: 5", "Transfer-Encoding: chunked"]),
                   req("POST", "/api/answer", "{}", extra=["Transfer-Encoding: gzip"]),
                   req("POST", "/api/answer", "{}",
                       extra=["Transfer-Encoding: chunked", "Transfer-Encoding: chunked"]),
                   req("GET", "/p", extra=[f"X-H{i}: v" for i in range(70)]),
                   req("GET", "/api/state", extra=[f"X-H{i}: v" for i in range(50)])),
    "forwarded": seq(req("GET", "/api/state", token="nonsense", extra=["X-Forwarded-For: 203.0.113.9"]),
                     req("GET", "/api/state", extra=["X-Forwarded-For: 1.1.1.1, 203.0.113.9",
                                                     "X-Forwarded-For: [2001:db8::5]"]),
                     req("GET", "/api/state", token="A" * 43,
                         extra=["X-Forwarded-For: nonsense, 127.0.0.1"]),
                     req("GET", "/p", token=None, extra=["X-Forwarded-For: ::ffff:192.0.2.7"])),
    "targets": seq(*[req("GET", p) for p in [
        "/api/state?x=1", "/p#frag", "/assets/app%2Ejs", "/%", "/%zz", "/a%00", "*",
        "http://example.org/p", "/api/clip/0?trial=1"]]),
}
for name, text in seeds.items():
    with open(os.path.join(d, name), "w", newline="") as f:
        f.write(text)
print(f"{len(seeds)} seeds in {d}")
