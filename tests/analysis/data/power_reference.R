# Reference values of the power tests in tests/analysis/PowerTest.cpp (R 4.2.2, pwr 1.3).
# Regenerate with:  Rscript tests/analysis/data/power_reference.R
# Design that reduces to two independent proportions: two groups of n participants, one answer
# each, no participant variability. "exact" is the power of chisq.test(correct = FALSE) (the
# two-proportion z-test) by enumeration of both binomials; "pwr" is pwr::pwr.2p.test (arcsine
# approximation), for comparison.
suppressPackageStartupMessages(library(pwr))
exact_power <- function(p1, p2, n, alpha = 0.05) {
  x <- 0:n
  d1 <- dbinom(x, n, p1); d2 <- dbinom(x, n, p2)
  pw <- 0
  for (i in x) for (j in x) {
    tab <- matrix(c(i, n - i, j, n - j), 2, byrow = TRUE)
    if (sum(tab[, 1]) == 0 || sum(tab[, 2]) == 0) next
    p <- suppressWarnings(chisq.test(tab, correct = FALSE)$p.value)
    if (p < alpha) pw <- pw + d1[i + 1] * d2[j + 1]
  }
  pw
}
for (cfg in list(c(0.8, 0.6, 40), c(0.7, 0.5, 60), c(0.9, 0.7, 30))) {
  p1 <- cfg[1]; p2 <- cfg[2]; n <- cfg[3]
  cat(sprintf("p1=%g p2=%g n=%d exact=%.10f pwr=%.10f  # pwr.2p.test(h = ES.h(%g, %g), n = %d, sig.level = 0.05)$power\n",
              p1, p2, n, exact_power(p1, p2, n), pwr.2p.test(h = ES.h(p1, p2), n = n, sig.level = 0.05)$power, p1, p2, n))
}
# Within-subject rating comparison that reduces to the paired t-test (PowerTest.cpp,
# RatingPowerReducesToThePairedTTest): each participant rates both conditions once, rating =
# bias (N(0, 1), per participant) + effect (0 / 0.6) + noise (N(0, 1)), not rounded, so the
# differences are N(0.6, 2) and pwr.t.test(type = "paired") gives the exact power.
for (n in c(12, 20, 40)) {
  r <- pwr.t.test(n = n, d = 0.6 / sqrt(2), sig.level = 0.05, type = "paired")
  cat(sprintf("n=%d power=%.10f  # pwr.t.test(n = %d, d = 0.6 / sqrt(2), sig.level = 0.05, type = \"paired\")$power\n",
              n, r$power, n))
}
