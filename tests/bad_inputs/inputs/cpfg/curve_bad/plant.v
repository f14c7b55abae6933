curve: profile.con
