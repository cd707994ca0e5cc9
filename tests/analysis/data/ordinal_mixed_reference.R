# Reference values of tests/analysis/OrdinalMixedTest.cpp (R 4.2, ordinal from Debian 12's
# r-cran-ordinal). Regenerate with (R is not needed to run the tests):
#   Rscript tests/analysis/data/ordinal_mixed_reference.R > tests/analysis/data/ordinal_mixed_reference.json
# Each case records its data, the R call that produced its values ("call", "lrt_call") and the
# warnings and messages R printed. nlminb's tolerances and the inner Newton loop's gradTol are
# tightened (ctrl) so that the values are the maximum of the likelihood, not where the default
# optimiser stopped: with clmm's default gradTol = 1e-6 the conditional modes carry an error
# that moves the Laplace log-likelihood by up to ~1e-6 and flat optima (variances, thresholds)
# by up to ~1e-3 relative, and an LRT by ~2e-3; "default" records
# the estimates and logLik of the same call with clmm's default control for comparison, and
# "warnings" what R prints for that default call and its summary() (the tightened optimiser
# adds inner-loop warnings of its own, which are not recorded).
suppressPackageStartupMessages({
  library(ordinal)
  library(jsonlite)
})
ctrl <- clmm.control(rel.tol = 1e-14, x.tol = 1e-12, eval.max = 1e5, iter.max = 1e5, gradTol = 1e-8)

capture <- function(expr) {
  notes <- character()
  value <- withCallingHandlers(
    tryCatch(expr, error = function(e) e),
    warning = function(w) { notes <<- c(notes, conditionMessage(w)); invokeRestart("muffleWarning") },
    message = function(m) { notes <<- c(notes, trimws(conditionMessage(m))); invokeRestart("muffleMessage") })
  list(value = value, notes = unique(notes))
}

# Ratings on 1..ncat: latent logistic (or normal) variable, participant intercepts with SD sd,
# condition within participants (each rates every condition nrep times) or between.
gen <- function(seed, np, nrep, ncond = 2, between = FALSE, sd = 1, effects = c(0, 0.8),
                ncat = 7, nsurf = 0, latent = rlogis) {
  set.seed(seed)
  parts <- sprintf("p%02d", seq_len(np))
  b <- rnorm(np, 0, sd)
  conds <- letters[seq_len(ncond)]
  surfs <- if (nsurf > 0) sprintf("s%d", seq_len(nsurf)) else "s1"
  rows <- list()
  for (i in seq_len(np)) {
    pc <- if (between) conds[(i - 1) %% ncond + 1] else conds
    g <- expand.grid(rep = seq_len(nrep), condition = pc, surface = surfs, stringsAsFactors = FALSE)
    g$participant <- parts[i]
    g$b <- b[i]
    rows[[i]] <- g
  }
  d <- do.call(rbind, rows)
  seff <- seq(0, by = -0.5, length.out = length(surfs))
  eta <- effects[match(d$condition, conds)] + seff[match(d$surface, surfs)] + d$b
  cuts <- seq(-(ncat - 2) / 2, (ncat - 2) / 2, length.out = ncat - 1)
  d$y <- findInterval(eta + latent(nrow(d)), cuts) + 1
  d[, c("y", "condition", "participant", "surface")]
}

coefTable <- function(m, which) {
  co <- summary(m)$coefficients
  rows <- if (which == "thresholds") seq_along(m$alpha) else length(m$alpha) + seq_along(m$beta)
  lapply(rows, function(i) {
    r <- list(name = rownames(co)[i], estimate = co[i, 1], se = co[i, 2], statistic = co[i, 3])
    if (which == "fixed") r$p <- co[i, 4]
    r
  })
}

cases <- list()
add <- function(x) cases[[length(cases) + 1]] <<- x

# The exact log-likelihood of the clmm (participant integrals by integrate(), no Laplace or
# quadrature approximation) at par = (thresholds, beta, sigma); X the fixed-effects columns.
exactLogLik <- function(par, k, X, p, Fn) {
  nt <- max(k) - 1
  th <- c(-Inf, par[seq_len(nt)], Inf)
  if (any(diff(th) <= 0)) return(-Inf)
  beta <- par[nt + seq_len(ncol(X))]
  s <- par[length(par)]
  eta <- as.vector(X %*% beta)
  tot <- 0
  for (g in unique(p)) {
    i <- which(p == g)
    f <- function(u) sapply(u, function(uu)
      exp(sum(log(Fn(th[k[i] + 1] - eta[i] - s * uu) - Fn(th[k[i]] - eta[i] - s * uu)))) * dnorm(uu))
    tot <- tot + log(integrate(f, -12, 12, rel.tol = 1e-12, subdivisions = 1000L)$value)
  }
  tot
}

clmm_case <- function(name, d, nAGQ = 1, link = "logit", surface = FALSE, levels = NULL,
                      compare = "full", se_tolerance = 1e-4) {
  lv <- if (is.null(levels)) sort(unique(d$y)) else levels
  d$y <- factor(d$y, levels = lv, ordered = TRUE)
  d$condition <- factor(d$condition)
  d$participant <- factor(d$participant)
  d$surface <- factor(d$surface)
  rhs <- if (surface) "condition + surface" else "condition"
  rhs0 <- if (surface) "surface" else "1"
  call1 <- sprintf("m1 <- clmm(y ~ %s + (1 | participant), data = d, link = \"%s\", nAGQ = %d, control = ctrl)",
                   rhs, link, nAGQ)
  out <- list(name = name, kind = "clmm", nAGQ = nAGQ, link = link, compare = compare,
              se_tolerance = se_tolerance, call = call1,
              data = list(y = as.integer(as.character(d$y)), condition = as.character(d$condition),
                          participant = as.character(d$participant)))
  if (surface) out$data$surface <- as.character(d$surface)
  if (!is.null(levels)) out$data$levels <- levels
  f1 <- as.formula(sprintf("y ~ %s + (1 | participant)", rhs))
  f0 <- as.formula(sprintf("y ~ %s + (1 | participant)", rhs0))
  r <- capture(clmm(f1, data = d, link = link, nAGQ = nAGQ, control = ctrl))
  if (inherits(r$value, "error")) {
    out$error <- conditionMessage(r$value)
    add(out)
    return(invisible())
  }
  m1 <- r$value
  s <- capture(summary(m1))
  out$fixed <- coefTable(m1, "fixed")
  out$thresholds <- coefTable(m1, "thresholds")
  out$random_variance <- as.numeric(VarCorr(m1)$participant)
  out$loglik <- as.numeric(logLik(m1))
  out$aic <- AIC(m1)
  out$max_grad <- max(abs(m1$gradient))
  out$cond_H <- s$value$info$cond.H
  dflt <- capture(clmm(f1, data = d, link = link, nAGQ = nAGQ))
  if (!inherits(dflt$value, "error")) {
    out$default <- list(estimate = unname(c(dflt$value$alpha, dflt$value$beta)),
                        loglik = as.numeric(logLik(dflt$value)))
    out$warnings <- unique(c(dflt$notes, capture(summary(dflt$value))$notes))
  }
  if (link == "cloglog") {
    # ordinal 2022.11-16's clmm does not evaluate the cloglog likelihood it reports: its logLik
    # differs from the exact integral at its own estimates by far more than a Laplace error.
    # The reference is then the exact likelihood, maximised by nlminb over integrate().
    Fc <- function(z) 1 - exp(-exp(z))
    k <- as.integer(d$y)
    X <- model.matrix(as.formula(sprintf("~ %s", rhs)), data = d)[, -1, drop = FALSE]
    par0 <- c(m1$alpha, m1$beta, sqrt(out$random_variance))
    ml <- nlminb(par0, function(q) -exactLogLik(q, k, X, as.character(d$participant), Fc),
                 lower = c(rep(-Inf, length(par0) - 1), 0), control = list(rel.tol = 1e-12))
    nt <- length(m1$alpha)
    out$exact <- list(
      call = "exactLogLik(par, ...) by integrate(rel.tol = 1e-12) per participant; nlminb",
      loglik_at_clmm_estimates = exactLogLik(par0, k, X, as.character(d$participant), Fc),
      ml = list(thresholds = ml$par[seq_len(nt)], fixed = ml$par[nt + seq_len(ncol(X))],
                random_variance = ml$par[length(ml$par)]^2, loglik = -ml$objective))
    out$compare <- "exact"
  }
  r0 <- capture(clmm(f0, data = d, link = link, nAGQ = nAGQ, control = ctrl))
  if (!inherits(r0$value, "error")) {
    # what anova(m0, m1) prints (anova.clmm cannot re-evaluate the models inside a function)
    lr <- 2 * (as.numeric(logLik(m1)) - as.numeric(logLik(r0$value)))
    df <- attr(logLik(m1), "df") - attr(logLik(r0$value), "df")
    out$lrt_call <- sprintf(paste("m0 <- clmm(y ~ %s + (1 | participant), ...same...);",
                                  "LR = 2 * (logLik(m1) - logLik(m0)), pchisq(LR, df, lower.tail = FALSE) as anova(m0, m1)"), rhs0)
    out$lrt <- list(statistic = lr, df = df, p = pchisq(lr, df, lower.tail = FALSE))
  }
  add(out)
}

# ordinary designs
clmm_case("within_np10_r3_logit_laplace", gen(1, 10, 3))
clmm_case("within_np10_r3_probit_laplace", gen(1, 10, 3, latent = rnorm), link = "probit")
clmm_case("within_np10_r3_cloglog_laplace", gen(1, 10, 3), link = "cloglog")
clmm_case("within_np10_r3_cloglog_agq25", gen(1, 10, 3), nAGQ = 25, link = "cloglog")
clmm_case("within_np10_r3_logit_agq5", gen(1, 10, 3), nAGQ = 5)
clmm_case("within_np12_r2_logit_agq10", gen(2, 12, 2, sd = 1.5), nAGQ = 10)
clmm_case("within_np12_r2_logit_agq25", gen(2, 12, 2, sd = 1.5), nAGQ = 25)
clmm_case("within_np12_r2_probit_agq7", gen(2, 12, 2, sd = 1.5, latent = rnorm), nAGQ = 7,
          link = "probit", se_tolerance = 1e-3)
clmm_case("within_np20_r2_3cond_logit", gen(3, 20, 2, ncond = 3, effects = c(0, 0.5, 1.2)))
clmm_case("within_np16_r1_surface_logit", gen(4, 16, 1, nsurf = 4), surface = TRUE)
clmm_case("between_np16_r4_logit", gen(5, 16, 4, between = TRUE, sd = 0.7))
clmm_case("within_np30_r2_5cat_logit", gen(6, 30, 2, ncat = 5, effects = c(0, -0.6)))
clmm_case("within_np40_r4_7cat_cloglog_agq3", gen(7, 40, 4, sd = 0.5), nAGQ = 3, link = "cloglog")
# degenerate designs
d <- gen(8, 8, 3); d$y <- 4
clmm_case("degenerate_all_answers_equal", d)
d <- gen(9, 10, 3); d$y <- pmin(d$y, 6)
clmm_case("degenerate_unused_top_category", d, levels = 1:7)
d <- gen(10, 10, 3); d$y[d$y == 3] <- 2
clmm_case("degenerate_unused_middle_category", d, levels = 1:7)
# R's standard errors here carry the noise of its finite-difference Hessian (deriv12, delta =
# 1e-4, over a likelihood whose inner Newton loop stops at gradTol): compared at 1e-3.
clmm_case("degenerate_three_participants", gen(11, 3, 4), se_tolerance = 1e-3)
clmm_case("degenerate_tiny_random_variance", gen(12, 12, 3, sd = 0.01))
clmm_case("degenerate_tiny_random_variance_agq5", gen(12, 12, 3, sd = 0.01), nAGQ = 5)
d <- gen(13, 10, 3); d$y[d$condition == "b"] <- 7; d$y[d$condition == "a"] <- pmin(d$y[d$condition == "a"], 6)
clmm_case("degenerate_separation", d, compare = "loglik")
clmm_case("degenerate_two_categories", gen(14, 15, 4, ncat = 2))

cat(toJSON(list(generated_by = "Rscript tests/analysis/data/ordinal_mixed_reference.R",
                r_version = R.version.string,
                ordinal = as.character(packageVersion("ordinal")),
                cases = cases), auto_unbox = TRUE, digits = NA, null = "null", na = "null"))
cat("\n")
