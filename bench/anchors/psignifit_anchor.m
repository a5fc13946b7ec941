% Cross-check of csfcal's study fits against psignifit 4 (Schuett et al. 2016), run under Octave.
function s = ifelse_str(y)
  if y, s = "yn  "; else s = "2afc"; end
end
% Usage: octave-cli -q bench/anchors/psignifit_anchor.m PSIGNIFIT_DIR LEVELS.csv FITS.csv
% (bench/anchors/check_psignifit.sh makes the CSVs with bench_anchor_data and runs this.)
% Like with like: psignifit's Weibull with threshPC = 1 - e^-1 is csfcal's
%   P = guess + (1 - guess - lapse)(1 - exp(-10^(beta (log10 c - t)))),  t = m / ln 10, beta = C / w,
% C = log(-log(0.05)) - log(-log(0.95)); eta (overdispersion) fixed at 0, gamma fixed at the guess;
% borders t in [xmin - 1, xmax + 1] log10, beta in [0.5, 20], lapse in [0, 0.06] (csfcal's limits).
% All priors flat in (m, w, lapse), as csfcal's (flat in t, in the width 1/beta and in the lapse):
% psignifit's MAP is then the maximum-likelihood fit -> compare t, beta, lapse and the log
% likelihood; its 95 % marginal credible interval of m (percentiles) is csfcal's marginal-posterior
% interval of t -> compare the ends and the widths.
1;
args = argv();
addpath(args{1});
lv = csvread(args{2});
fits = csvread(args{3});
C = log(-log(0.05)) - log(-log(0.95));
flat = @(x) ones(size(x));
printf('id design levels trials | dt_ML  dbeta_ML/beta  dlapse  dloglik | t_lo: ours psig  t_hi: ours psig | dwidth%%\n');
res = [];
for r = 1:rows(fits)
  id = fits(r, 1); yesno = fits(r, 2); guess = fits(r, 5);
  d = lv(lv(:, 1) == id, 2:4);
  data = [10 .^ d(:, 1), d(:, 3), d(:, 2)];
  o = struct();
  o.sigmoidName = 'weibull';
  o.expType = 'YesNo';
  o.threshPC = 1 - exp(-1);
  o.fixedPars = [NaN; NaN; NaN; guess; 0];
  o.borders = [log(10) * (min(d(:, 1)) - 1), log(10) * (max(d(:, 1)) + 1); C / 20, C / 0.5; 0, 0.06; NaN, NaN; NaN, NaN];
  o.stepN = [120, 80, 25, 1, 1];
  o.mbStepN = [60, 50, 13, 1, 1];
  o.instantPlot = 0;
  o.priors = {flat, flat, flat, flat, flat};
  warning('off', 'all');
  a = psignifit(data, o);
  t = a.Fit(1) / log(10); beta = C / a.Fit(2); lapse = a.Fit(3);
  p = guess + (1 - guess - lapse) .* (1 - exp(-10 .^ (beta .* (d(:, 1) - t))));
  p = min(max(p, 1e-12), 1 - 1e-12);
  ll = sum(d(:, 3) .* log(p) + (d(:, 2) - d(:, 3)) .* log(1 - p));
  ci = a.conf_Intervals(1, :, 1) / log(10);
  e = [id, yesno, fits(r, 3), fits(r, 4), t - fits(r, 6), (beta - fits(r, 7)) / fits(r, 7), lapse - fits(r, 8), ...
       ll - fits(r, 9), fits(r, 12), ci(1), fits(r, 13), ci(2), 100 * ((ci(2) - ci(1)) / (fits(r, 13) - fits(r, 12)) - 1)];
  res(end + 1, :) = e;
  printf('%2d %s %d x %2d | %+.4f %+.3f %+.4f %+.3f | %.4f %.4f  %.4f %.4f | %+.1f\n', e(1), ...
         ifelse_str(yesno), e(3), e(4), e(5), e(6), e(7), e(8), e(9), e(10), e(11), e(12), e(13));
end
printf('summary over %d data sets: max |dt_ML| %.4f log10, median |dbeta|/beta %.3f, max |dlapse| %.4f, max dloglik (psignifit - csfcal) %+.3f\n', ...
       rows(res), max(abs(res(:, 5))), median(abs(res(:, 6))), max(abs(res(:, 7))), max(res(:, 8)));
printf('interval ends: max |difference| %.4f log10 (lower) %.4f (upper); width ratio median %+.1f %%, range [%+.1f, %+.1f] %%\n', ...
       max(abs(res(:, 9) - res(:, 10))), max(abs(res(:, 11) - res(:, 12))), median(res(:, 13)), min(res(:, 13)), max(res(:, 13)));
% Limits (fail = exit 1): csfcal's ML never worse than psignifit's MAP-with-flat-priors by more than
% 0.01 log-likelihood units (where the likelihood is flat the parameters may differ, as in a slope
% traded against the lapse); interval ends within 0.03 log10 (psignifit's grid is coarser in t).
bad = find(res(:, 8) > 0.01 | abs(res(:, 9) - res(:, 10)) > 0.03 | abs(res(:, 11) - res(:, 12)) > 0.03);
if ~isempty(bad)
  printf('DISAGREE: data sets %s\n', mat2str(res(bad, 1)'));
  exit(1);
end
printf('ok\n');
