# Reference values of tests/analysis/MixedModelsTest.cpp (R 4.2.2, lme4, lmerTest, Debian 12).
# Regenerate with:  Rscript tests/analysis/data/mixed_models_reference.R > tests/analysis/data/mixed_models_reference.json
# Every case records its data, the R call that produced its values ("call", "lrt_call") and the
# warnings and messages R printed. Optimiser tolerances are tightened (ctrlG, ctrlL) so that the
# values are the maximum of the likelihood to ~1e-8, not where the default optimiser stopped;
# "default" records the estimates of the same call with lme4's default control for comparison.
# tolPwrss = 1e-13: with the default 1e-7, lme4's PIRLS stops early and its Laplace deviance
# (nAGQ = 1) carries an error of ~1e-6 that moves finite-difference standard errors by up to
# ~2e-3 (relative) and flat optima by ~1e-3; with it, lme4 agrees with the exact Laplace
# approximation to ~1e-7. (Adaptive quadrature, nAGQ > 1, is insensitive to it.)
suppressPackageStartupMessages({
  library(lme4)
  library(lmerTest)
  library(jsonlite)
})
ctrlG <- glmerControl(optimizer = "nloptwrap", tolPwrss = 1e-13,
                      optCtrl = list(xtol_rel = 1e-12, ftol_rel = 1e-15, ftol_abs = 1e-13, maxeval = 1e5))
ctrlL <- lmerControl(optimizer = "nloptwrap",
                     optCtrl = list(xtol_rel = 1e-12, ftol_rel = 1e-15, ftol_abs = 1e-13, maxeval = 1e5))

capture <- function(expr) {
  notes <- character()
  value <- withCallingHandlers(
    tryCatch(expr, error = function(e) e),
    warning = function(w) { notes <<- c(notes, conditionMessage(w)); invokeRestart("muffleWarning") },
    message = function(m) { notes <<- c(notes, trimws(conditionMessage(m))); invokeRestart("muffleMessage") })
  list(value = value, notes = unique(notes))
}

# Binary answers: np participants, ntrial trials per participant and cell; condition between
# participants (groups, as in the studies) or within; optional surface factor (within).
gen <- function(seed, np, ntrial, ncond = 2, between = TRUE, sd = 1, effects = c(0, 0.8),
                base = 0.5, nsurf = 0, binary = TRUE, resid = 1) {
  set.seed(seed)
  parts <- sprintf("p%02d", seq_len(np))
  b <- rnorm(np, 0, sd)
  conds <- letters[seq_len(ncond)]
  surfs <- if (nsurf > 0) sprintf("s%d", seq_len(nsurf)) else "s1"
  rows <- list()
  for (i in seq_len(np)) {
    pc <- if (between) conds[(i - 1) %% ncond + 1] else conds
    g <- expand.grid(trial = seq_len(ntrial), condition = pc, surface = surfs, stringsAsFactors = FALSE)
    g$participant <- parts[i]
    g$b <- b[i]
    rows[[i]] <- g
  }
  d <- do.call(rbind, rows)
  seff <- seq(0, by = -0.4, length.out = length(surfs))
  eta <- base + effects[match(d$condition, conds)] + seff[match(d$surface, surfs)] + d$b
  d$y <- if (binary) rbinom(nrow(d), 1, plogis(eta)) else round(4 + eta + rnorm(nrow(d), 0, resid), 2)
  d$condition <- factor(d$condition)
  d$participant <- factor(d$participant)
  d$surface <- factor(d$surface)
  d[, c("y", "condition", "participant", "surface")]
}

datalist <- function(d, surface) {
  out <- list(y = d$y, condition = as.character(d$condition), participant = as.character(d$participant))
  if (surface) out$surface <- as.character(d$surface)
  out
}

coefs <- function(m, df) {
  co <- summary(m)$coefficients
  lapply(seq_len(nrow(co)), function(i) {
    r <- list(name = rownames(co)[i], estimate = co[i, 1], se = co[i, 2])
    if (df) { r$df <- co[i, 3]; r$statistic <- co[i, 4]; r$p <- co[i, 5] }
    else { r$statistic <- co[i, 3]; r$p <- co[i, 4] }
    r
  })
}

cases <- list()
add <- function(x) cases[[length(cases) + 1]] <<- x

glmm_case <- function(name, d, nAGQ = 1, surface = FALSE, compare = "full") {
  f1 <- if (surface) y ~ condition + surface + (1 | participant) else y ~ condition + (1 | participant)
  f0 <- if (surface) y ~ surface + (1 | participant) else y ~ 1 + (1 | participant)
  out <- list(name = name, kind = "glmm", nAGQ = nAGQ, compare = compare,
              call = sprintf("m1 <- glmer(%s, data = d, family = binomial, nAGQ = %d, control = ctrlG)",
                             paste(deparse(f1), collapse = ""), nAGQ),
              data = datalist(d, surface))
  c1 <- capture(glmer(f1, data = d, family = binomial, nAGQ = nAGQ, control = ctrlG))
  if (inherits(c1$value, "error")) { out$error <- conditionMessage(c1$value); add(out); return(invisible()) }
  m1 <- c1$value
  cs <- capture(coefs(m1, FALSE))
  out$fixed <- cs$value
  out$random_variance <- as.numeric(VarCorr(m1)$participant)
  out$loglik <- as.numeric(logLik(m1))
  out$aic <- AIC(m1)
  out$warnings <- as.list(unique(c(c1$notes, cs$notes)))
  out$singular <- isSingular(m1)
  cd <- capture(glmer(f1, data = d, family = binomial, nAGQ = nAGQ))
  if (!inherits(cd$value, "error")) out$default <- list(estimate = unname(fixef(cd$value)), warnings = as.list(cd$notes))
  c0 <- capture(glmer(f0, data = d, family = binomial, nAGQ = nAGQ, control = ctrlG))
  if (!inherits(c0$value, "error")) {
    a <- anova(c0$value, m1)
    out$lrt_call <- sprintf("m0 <- glmer(%s, ...same...); anova(m0, m1)", paste(deparse(f0), collapse = ""))
    out$lrt <- list(statistic = a$Chisq[2], df = a$Df[2], p = a$`Pr(>Chisq)`[2])
  }
  add(out)
}

lmm_case <- function(name, d, surface = FALSE, compare = "full") {
  f1 <- if (surface) y ~ condition + surface + (1 | participant) else y ~ condition + (1 | participant)
  f0 <- if (surface) y ~ surface + (1 | participant) else y ~ 1 + (1 | participant)
  out <- list(name = name, kind = "lmm", compare = compare,
              call = sprintf("m1 <- lmerTest::lmer(%s, data = d, REML = TRUE, control = ctrlL)",
                             paste(deparse(f1), collapse = "")),
              data = datalist(d, surface))
  c1 <- capture(lmerTest::lmer(f1, data = d, REML = TRUE, control = ctrlL))
  if (inherits(c1$value, "error")) { out$error <- conditionMessage(c1$value); add(out); return(invisible()) }
  m1 <- c1$value
  cs <- capture(coefs(m1, TRUE))
  out$fixed <- cs$value
  vc <- as.data.frame(VarCorr(m1))
  out$random_variance <- vc$vcov[vc$grp == "participant"]
  out$residual_variance <- vc$vcov[vc$grp == "Residual"]
  out$loglik <- as.numeric(logLik(m1))
  out$aic <- AIC(m1)
  out$warnings <- as.list(unique(c(c1$notes, cs$notes)))
  out$singular <- isSingular(m1)
  c0 <- capture(lmerTest::lmer(f0, data = d, REML = TRUE, control = ctrlL))
  if (!inherits(c0$value, "error")) {
    a <- suppressMessages(anova(c0$value, m1))
    out$lrt_call <- sprintf("m0 <- lmerTest::lmer(%s, ...same...); anova(m0, m1)  # refits by ML", paste(deparse(f0), collapse = ""))
    out$lrt <- list(statistic = a$Chisq[2], df = a$Df[2], p = a$`Pr(>Chisq)`[2])
  }
  add(out)
}

# ---- logistic, Laplace and AGQ, regular designs
k <- 0
for (np in c(8, 12, 20, 40)) for (nt in c(4, 8)) {
  k <- k + 1
  d <- gen(100 + k, np, nt, sd = 1)
  glmm_case(sprintf("glmm_between_np%d_nt%d_laplace", np, nt), d, 1)
  glmm_case(sprintf("glmm_between_np%d_nt%d_agq10", np, nt), d, 10)
}
for (np in c(10, 30)) {
  d <- gen(200 + np, np, 4, ncond = 3, between = TRUE, sd = 1.5, effects = c(0, 0.5, 1.2))
  glmm_case(sprintf("glmm_3groups_np%d_laplace", np), d, 1)
  glmm_case(sprintf("glmm_3groups_np%d_agq5", np), d, 5)
}
for (np in c(10, 24)) {
  d <- gen(300 + np, np, 3, ncond = 2, between = FALSE, sd = 1.2, effects = c(0, -0.7))
  glmm_case(sprintf("glmm_within_np%d_laplace", np), d, 1)
  glmm_case(sprintf("glmm_within_np%d_agq25", np), d, 25)
}
d <- gen(401, 16, 2, ncond = 2, between = TRUE, sd = 0.8, nsurf = 4)
glmm_case("glmm_surface_np16_laplace", d, 1, surface = TRUE)
glmm_case("glmm_surface_np16_agq10", d, 10, surface = TRUE)
d <- gen(402, 60, 8, ncond = 2, between = TRUE, sd = 1, nsurf = 2)
glmm_case("glmm_surface_np60_laplace", d, 1, surface = TRUE)
glmm_case("glmm_surface_np60_agq10", d, 10, surface = TRUE)
d <- gen(403, 60, 16, ncond = 2, between = TRUE, sd = 1)
glmm_case("glmm_bench_np60_nt16_agq10", d, 10)
d <- gen(404, 30, 6, ncond = 2, between = TRUE, sd = 3, effects = c(0, 1.5))
glmm_case("glmm_large_variance_laplace", d, 1)
glmm_case("glmm_large_variance_agq15", d, 15)
# ---- logistic, degenerate
d <- gen(501, 10, 4, sd = 0)
glmm_case("glmm_singular_laplace", d, 1)
d <- gen(502, 6, 3, sd = 0, effects = c(0, 0.3))
glmm_case("glmm_singular_small_agq10", d, 10)
d <- gen(503, 10, 4); d$y[] <- 1L
glmm_case("glmm_all_correct", d, 1, compare = "loglik")
d <- gen(504, 12, 4, base = 0, effects = c(0, 0)); d$y[d$condition == "b"] <- 1L
glmm_case("glmm_separation_condition", d, 1, compare = "loglik")
d <- gen(505, 1, 20, ncond = 2, between = FALSE)
glmm_case("glmm_one_participant", d, 1, compare = "error")
d <- gen(506, 10, 4); d$condition[] <- "a"; d$condition <- factor(d$condition)
glmm_case("glmm_one_condition", d, 1, compare = "error")
d <- gen(507, 8, 1, ncond = 2, between = TRUE, sd = 1)
glmm_case("glmm_one_trial_each", d, 1, compare = "loglik")  # not identified: one answer per participant

# ---- linear (ratings)
k <- 0
for (np in c(6, 12, 20, 40)) for (nt in c(2, 6)) {
  k <- k + 1
  d <- gen(600 + k, np, nt, sd = 1, binary = FALSE)
  lmm_case(sprintf("lmm_between_np%d_nt%d", np, nt), d)
}
for (np in c(9, 30)) {
  d <- gen(700 + np, np, 3, ncond = 3, between = TRUE, sd = 0.7, effects = c(0, 0.4, -0.6), binary = FALSE)
  lmm_case(sprintf("lmm_3groups_np%d", np), d)
}
for (np in c(8, 25)) {
  d <- gen(800 + np, np, 2, ncond = 2, between = FALSE, sd = 1.3, effects = c(0, 0.5), binary = FALSE)
  lmm_case(sprintf("lmm_within_np%d", np), d)
}
d <- gen(901, 16, 2, ncond = 2, between = TRUE, sd = 0.8, nsurf = 3, binary = FALSE)
lmm_case("lmm_surface_np16", d, surface = TRUE)
d <- gen(902, 20, 2, ncond = 2, between = FALSE, sd = 0.5, nsurf = 4, binary = FALSE)
lmm_case("lmm_surface_within_np20", d, surface = TRUE)
d <- gen(903, 24, 4, ncond = 2, between = TRUE, sd = 1, binary = FALSE)
d$y <- pmin(pmax(round(d$y), 1), 7)
lmm_case("lmm_likert_1_7", d)
d <- gen(904, 14, 3, ncond = 2, between = TRUE, sd = 2, resid = 0.3, binary = FALSE)
lmm_case("lmm_large_between_variance", d)
# ---- linear, degenerate
d <- gen(951, 10, 3, sd = 0, binary = FALSE)
lmm_case("lmm_singular", d)
d <- gen(952, 6, 2, sd = 0, resid = 2, binary = FALSE)
lmm_case("lmm_singular_small", d)
d <- gen(953, 1, 10, between = FALSE, binary = FALSE)
lmm_case("lmm_one_participant", d, compare = "error")
d <- gen(954, 8, 1, between = TRUE, binary = FALSE)
lmm_case("lmm_one_observation_each", d, compare = "error")
d <- gen(955, 10, 3, binary = FALSE); d$condition[] <- "a"; d$condition <- factor(d$condition)
lmm_case("lmm_one_condition", d, compare = "error")
d <- gen(956, 10, 3, binary = FALSE); d$y[] <- d$y[1] + 0
lmm_case("lmm_all_equal", d, compare = "error")
d <- gen(957, 12, 3, ncond = 2, between = TRUE, binary = FALSE); d$y[d$condition == "b"] <- 5
lmm_case("lmm_constant_group", d)

cat(toJSON(list(generated_by = "Rscript tests/analysis/data/mixed_models_reference.R",
                r_version = R.version.string,
                lme4 = as.character(packageVersion("lme4")),
                lmerTest = as.character(packageVersion("lmerTest")),
                cases = cases),
           auto_unbox = TRUE, digits = NA, null = "null", na = "null", pretty = FALSE))
cat("\n")
