% Psychtoolbox QUEST on the same simulated observers as bench/bench_observer.c.
% Usage: octave-cli -q bench/quest/run_quest.m TRUTH.csv OUT.csv
% TRUTH.csv rows (no header): observer_id,cell,true_log10,guess_log10,visible,n_alternatives
% A header line "#params,slope,lapse,log10_cmax,log10_cmin,guess_sd,seeds,b1,b2,..." comes first.
% One QUEST per cell (QuestCreate/QuestUpdate/QuestQuantile/QuestMean), cells interleaved
% round-robin, the budget split evenly over the cells; the simulated forced-choice observer uses
% the same Weibull as ours: P = g + (1 - g - lapse) * (1 - exp(-10^(slope*(x - t)))), with the
% guess rate g = 1/n_alternatives of the cell (two intervals: 1/2, four places: 1/4).
% Writes OUT.csv rows: observer_id,budget,rms_log10 (RMS over seeds of the per-seed RMS over
% visible cells, QuestMean estimates clamped to the display's max contrast).
1;
addpath('/usr/share/psychtoolbox-3/Quest');
args = argv();
if numel(args) < 2
  error('usage: run_quest.m TRUTH.csv OUT.csv');
end
fid = fopen(args{1}, 'r');
hdr = strsplit(strtrim(fgetl(fid)), ',');
slope = str2double(hdr{2}); lapse = str2double(hdr{3});
lcmax = str2double(hdr{4}); lcmin = str2double(hdr{5});
guess_sd = str2double(hdr{6});
nseeds = str2double(hdr{7});
budgets = cellfun(@str2double, hdr(8:end));
data = textscan(fid, '%f,%f,%f,%f,%f,%f');
fclose(fid);
obs = data{1}; truth = data{3}; guess = data{4}; vis = data{5}; nalt = data{6};
% QUEST's psychometric function: P = delta*gamma + (1-delta)*(1-(1-gamma)*exp(-10^(beta*(x-t'))))
% = gamma + (1-delta)(1-gamma) F equals ours with gamma = g, delta = lapse/(1-g) (2*lapse for
% two intervals); at x = t it gives pThreshold = g + (1 - g - lapse)(1 - e^-1), set per cell below.
out = fopen(args{2}, 'w');
for o = unique(obs)'
  sel = find(obs == o);
  ncell = numel(sel);
  for b = budgets
    rms_seed = zeros(1, nseeds);
    for seed = 1:nseeds
      rand('state', 1000 * o + 7 * b + seed);
      q = cell(1, ncell);
      for c = 1:ncell
        g = 1 / nalt(sel(c));
        pthr = g + (1 - g - lapse) * (1 - exp(-1));
        q{c} = QuestCreate(guess(sel(c)), guess_sd, pthr, slope, lapse / (1 - g), g, 0.01, 5);
        q{c}.normalizePdf = 1;
      end
      for k = 0:(b - 1)
        c = mod(k, ncell) + 1;
        x = QuestQuantile(q{c});
        x = min(max(x, lcmin), lcmax);
        t = truth(sel(c));
        seen = 0;
        if t < 0
          seen = 1 - exp(-10 ^ (slope * (x - t)));
        end
        g = 1 / nalt(sel(c));
        correct = rand() < g + (1 - g - lapse) * seen;
        q{c} = QuestUpdate(q{c}, x, correct);
      end
      err2 = []; 
      for c = 1:ncell
        if vis(sel(c))
          est = min(QuestMean(q{c}), lcmax);
          err2(end + 1) = (est - truth(sel(c))) ^ 2;
        end
      end
      rms_seed(seed) = sqrt(mean(err2));
    end
    fprintf(out, '%d,%d,%.6f\n', o, b, sqrt(mean(rms_seed .^ 2)));
  end
end
fclose(out);
