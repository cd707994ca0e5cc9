// SPDX-License-Identifier: GPL-3.0-or-later
// Underfoot FSR shoes: four force-sensing resistors (left heel, left toe, right heel, right toe)
// sampled at 1 kHz and streamed over USB serial in the Underfoot line protocol v1
// (docs/reference/sensors.md, "Shoes: the serial line protocol"):
//
//   # underfoot-shoes 1 rate_hz=1000 adc_bits=10\r\n                (once, at start-up)
//   <t_ms>,<lh>,<lt>,<rh>,<rt>\r\n                                   (every 1 ms)
//
// An Uno/Diecimila resets when the host opens the port (DTR), so every reader sees the header.
// It is not repeated: 46 header bytes plus a frame do not fit the 64-byte transmit buffer
// within one millisecond, and sampling must never wait for the port.
//
// t_ms is the sample clock: it advances by exactly 1 per scheduled sample, also for samples that
// were skipped (loop overrun, or the serial buffer full), so the host counts every lost frame as
// a gap in t_ms. Sampling never waits for the serial port.
//
// Board: Arduino Uno / Diecimila / Nano (ATmega328P or 168, 16 MHz). 500000 baud is exact on a
// 16 MHz AVR (UBRR = 3 with U2X: 0 % error), unlike 115200 (-3.5 %) or 250000/1000000 on some
// USB bridges; a frame is at most 30 bytes = 300 bit times, 0.6 ms at 500000 baud, so 1 kHz fits
// with a 40 % margin (115200 baud would carry only 11 bytes per millisecond).
//
// Wiring (per sensor, as in the haptic-shoes papers): FSR from +5 V to the analog pin, a 10 kOhm
// trimmer from the pin to GND (set it so that standing gives about half scale), optionally
// 100 nF from the pin to GND against cable noise. A0 = left heel, A1 = left toe, A2 = right heel,
// A3 = right toe. More pressure -> lower FSR resistance -> higher reading.

const uint8_t kPins[4] = {A0, A1, A2, A3};
const unsigned long kPeriodUs = 1000; // 1 kHz
const uint8_t kMaxLineBytes = 32;     // a v1 frame is at most 30 bytes

unsigned long nextUs;
unsigned long tMs = 0; // the sample clock sent as t_ms

void setup() {
  // ADC clock 16 MHz / 64 = 250 kHz: one conversion ~52 us, four well inside a millisecond,
  // still full 10-bit accuracy (the default /128 would spend 0.42 ms of every 1 ms reading).
  ADCSRA = (ADCSRA & ~0x07) | 0x06;
  Serial.begin(500000);
  while (!Serial) {
  } // boards with native USB wait for the host
  Serial.print(F("# underfoot-shoes 1 rate_hz=1000 adc_bits=10\r\n"));
  Serial.flush();
  nextUs = micros();
}

void loop() {
  const unsigned long now = micros();
  if ((long)(now - nextUs) < 0) return; // not yet
  // Fell behind by more than a period: skip those samples (the host sees a gap in t_ms).
  const unsigned long lateUs = now - nextUs;
  if (lateUs >= kPeriodUs) {
    const unsigned long skipped = lateUs / kPeriodUs;
    tMs += skipped;
    nextUs += skipped * kPeriodUs;
  }
  nextUs += kPeriodUs;

  uint16_t v[4];
  for (uint8_t i = 0; i < 4; ++i) v[i] = analogRead(kPins[i]);

  // Never block: if the USB side does not drain, drop this frame (a gap in t_ms).
  if (Serial.availableForWrite() >= kMaxLineBytes) {
    char line[kMaxLineBytes + 2];
    const int n = snprintf(line, sizeof line, "%lu,%u,%u,%u,%u\r\n", tMs, v[0], v[1], v[2], v[3]);
    Serial.write(line, n);
  }
  ++tMs;
}
